#include "render/GpuScene.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include <glm/gtc/matrix_inverse.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/Log.h"
#include "core/camera/CalibrationFile.h"
#include "core/camera/EquirectProjection.h"
#include "core/image/ImageIO.h"

namespace mirage::render {
namespace {

using Vertex = GpuSceneVertex;

// The materials the real-time renderer draws as specular objects (traced rays, photons,
// reflected / refracted VPLs): mirrors, rough reflectors and glass.
bool isSpecularMaterial(const Material& m) {
    return m.isMirror() || m.isRoughReflector() || m.isTransmissive();
}

GpuMaterial toGpu(const Material& m) {
    GpuMaterial g{};
    g.baseColor = m.baseColor;
    g.emissive = m.emissive;
    g.roughness = m.roughness;
    g.metallic = m.metallic;
    // KHR_materials_transmission / ior / volume. An infinite (or non-positive) attenuation
    // distance means no absorption: stored as 0.
    // A translucent material is not glass whatever its transmission factor
    // (Material::isTransmissive).
    g.transmission = m.isTranslucent() ? 0.0f : std::clamp(m.transmission, 0.0f, 1.0f);
    g.ior = std::isfinite(m.ior) && m.ior > 0.0f ? m.ior : 1.5f;
    g.attenuationDistance = std::isfinite(m.attenuationDistance) && m.attenuationDistance > 0.0f
                                ? m.attenuationDistance
                                : 0.0f;
    g.attenuationColor = glm::clamp(m.attenuationColor, 0.0f, 1.0f);
    g.mirror = m.isMirror() ? 1 : 0;
    g.specular = isSpecularMaterial(m) ? 1 : 0;
    g.thickness = std::max(m.thickness, 0.0f);
    g.translucent = m.isTranslucent() ? 1 : 0;
    return g;
}

bool finite(const glm::mat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

// SH9 basis (real, orthonormal), order L00, L1-1, L10, L11, L2-2, L2-1, L20, L21, L22.
void shBasis(const glm::vec3& d, float out[9]) {
    out[0] = 0.282095f;
    out[1] = 0.488603f * d.y;
    out[2] = 0.488603f * d.z;
    out[3] = 0.488603f * d.x;
    out[4] = 1.092548f * d.x * d.y;
    out[5] = 1.092548f * d.y * d.z;
    out[6] = 0.315392f * (3.0f * d.z * d.z - 1.0f);
    out[7] = 1.092548f * d.x * d.z;
    out[8] = 0.546274f * (d.x * d.x - d.y * d.y);
}

}  // namespace

std::vector<glm::vec3> GpuScene::projectEquirectToSH(const cv::Mat& img, float intensity,
                                                     double rotationYDeg) {
    MR_CHECK(img.type() == CV_32FC3, "environment image must be linear RGB float");
    std::vector<glm::vec3> sh(9, glm::vec3(0.0f));
    const double rot = rotationYDeg * 3.14159265358979 / 180.0;
    // Sub-sample large maps: SH9 is very low frequency, 256 columns are plenty.
    const int step = std::max(1, img.cols / 256);
    double weightSum = 0.0;
    for (int y = 0; y < img.rows; y += step) {
        const double lat = (0.5 - (y + 0.5) / img.rows) * 3.14159265358979;  // +pi/2 = +Y
        const double dOmega = std::cos(lat) * (3.14159265358979 / img.rows) *
                              (2.0 * 3.14159265358979 / img.cols) * step * step;
        const auto* row = img.ptr<cv::Vec3f>(y);
        for (int x = 0; x < img.cols; x += step) {
            const double phi = ((x + 0.5) / img.cols - 0.5) * 2.0 * 3.14159265358979 + rot;
            glm::vec3 d(float(std::cos(lat) * std::sin(phi)), float(std::sin(lat)),
                        float(-std::cos(lat) * std::cos(phi)));
            glm::vec3 c(row[x][0], row[x][1], row[x][2]);
            if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)) continue;
            float b[9];
            shBasis(d, b);
            for (int i = 0; i < 9; ++i) sh[size_t(i)] += c * (b[i] * float(dOmega));
            weightSum += dOmega;
        }
    }
    // Normalise the quadrature to exactly 4 pi so a constant map gives exact irradiance.
    const float norm = weightSum > 0 ? float(4.0 * 3.14159265358979 / weightSum) : 0.0f;
    for (auto& c : sh) c *= norm * intensity;
    return sh;
}

GpuScene::GpuScene(const Scene& scene, int surfacePoints, int environmentLightSlots)
    : environmentLightSlots_(environmentLightSlots), vao_("scene vao") {
    uploadTextures(scene);
    const int materialCount = uploadMaterials(scene);
    // Geometry: one vertex and one index buffer for all primitives.
    std::vector<Vertex> verts;
    std::vector<uint32_t> idx;
    const std::vector<std::vector<Range>> meshRanges =
        uploadGeometry(scene, materialCount, verts, idx);
    buildDraws(scene, meshRanges);
    buildLights(scene);
    uploadSpecularDraws();
    buildSurfacePoints(verts, idx, surfacePoints);
    uploadEnvironment(scene);
}

// Textures (baseColor ones are sRGB-encoded: GL decodes them to linear when sampled).
void GpuScene::uploadTextures(const Scene& scene) {
    white_ = gl::Texture::create2D("white 1x1", 1, 1, GL_RGBA8);
    const unsigned char whitePx[4] = {255, 255, 255, 255};
    white_.upload(GL_RGBA, GL_UNSIGNED_BYTE, whitePx);
    for (const Texture& t : scene.textures) {
        if (t.width <= 0 || t.height <= 0 ||
            t.pixels.size() != size_t(t.width) * size_t(t.height) * 4) {
            textures_.push_back(gl::Texture());
            continue;
        }
        int levels = 1;
        while ((std::max(t.width, t.height) >> levels) > 0) ++levels;
        gl::Texture g = gl::Texture::create2D("scene texture " + t.name, t.width, t.height,
                                              t.srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, levels);
        g.upload(GL_RGBA, GL_UNSIGNED_BYTE, t.pixels.data());
        glGenerateTextureMipmap(g.id());
        g.setWrap(GL_REPEAT);
        textures_.push_back(std::move(g));
    }
}

// Materials: slot 0 is the glTF default material, slot i+1 is scene.materials[i]. Returns the
// slot count.
int GpuScene::uploadMaterials(const Scene& scene) {
    std::vector<GpuMaterial> mats;
    mats.push_back(toGpu(Material()));  // glTF default: white, metallic 1, roughness 1
    // Translucent materials are shaded by the translucency pass (render/passes/translucency).
    for (const Material& m : scene.materials) mats.push_back(toGpu(m));
    materials_ = gl::Buffer("scene materials", mats.size() * sizeof(GpuMaterial), mats.data());
    media_.resize(mats.size());
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        const Material& m = scene.materials[i];
        if (!m.isTranslucent()) continue;
        GpuMedium& g = media_[i + 1];
        g.present = true;
        g.extinction = m.scattering.extinction;
        g.albedo = m.scattering.albedo;
        g.ior = std::isfinite(m.ior) && m.ior > 0.0f ? m.ior : 1.0f;
        if (const DensityGrid* d = m.scattering.density.get()) {
            g.hasDensity = true;
            g.boundsMin = d->boundsMin;
            g.boundsMax = d->boundsMax;
            g.gridSize = glm::ivec3(d->nx, d->ny, d->nz);
            g.density = gl::Texture::create3D(m.name + " density", d->nx, d->ny, d->nz, GL_R32F);
            g.density.upload(GL_RED, GL_FLOAT, d->values.data());
        }
    }

    return int(mats.size());
}

// Every primitive's vertices and indices appended to verts / idx (uploaded once), and per mesh
// the range of each of its primitives with its material, texture and local bounding sphere.
std::vector<std::vector<GpuScene::Range>> GpuScene::uploadGeometry(const Scene& scene,
                                                                   int materialCount,
                                                                   std::vector<Vertex>& verts,
                                                                   std::vector<uint32_t>& idx) {
    std::vector<std::vector<Range>> meshRanges(scene.meshes.size());
    for (size_t mi = 0; mi < scene.meshes.size(); ++mi) {
        for (const Primitive& p : scene.meshes[mi].primitives) {
            if (p.positions.empty() || p.indices.empty()) continue;
            Range r{GLint(verts.size()),
                    GLuint(idx.size()),
                    GLsizei(p.indices.size()),
                    p.material + 1,
                    -1,
                    glm::vec3(0.0f),
                    0.0f,
                    false,
                    false,
                    false,
                    false,
                    false,
                    -1};
            const Material& mat = scene.material(p.material);
            // Mirror: metallic ~1 with low roughness; rough reflector: a metal up to
            // Material::kRoughReflectorMaxRoughness (fuzzy reflections); glass: any transmission
            // (rough glass too).
            r.specular = isSpecularMaterial(mat);
            r.transmissive = mat.isTransmissive() && !mat.isMirror();
            r.roughReflector = mat.isRoughReflector();
            r.roughGlass = mat.isRoughGlass();
            r.translucent = mat.isTranslucent();
            const std::vector<glm::vec2>& uvs = mat.baseColorTexture.texCoord == 1 ? p.uv1 : p.uv0;
            if (mat.baseColorTexture.valid() &&
                size_t(mat.baseColorTexture.texture) < scene.textures.size() &&
                uvs.size() == p.positions.size())
                r.texture = mat.baseColorTexture.texture;
            // The mesh carries one UV set, the base colour's: a metallic-roughness texture on
            // another set is not sampled (docs/scene.md).
            if (mat.metallicRoughnessTexture.valid() &&
                size_t(mat.metallicRoughnessTexture.texture) < scene.textures.size() &&
                mat.metallicRoughnessTexture.texCoord == mat.baseColorTexture.texCoord &&
                uvs.size() == p.positions.size())
                r.metallicRoughnessTexture = mat.metallicRoughnessTexture.texture;
            glm::vec3 lo(1e30f), hi(-1e30f);
            for (size_t i = 0; i < p.positions.size(); ++i) {
                glm::vec3 n = i < p.normals.size() ? p.normals[i] : glm::vec3(0, 1, 0);
                glm::vec2 uv = i < uvs.size() ? uvs[i] : glm::vec2(0.0f);
                verts.push_back({p.positions[i], n, uv});
                lo = glm::min(lo, p.positions[i]);
                hi = glm::max(hi, p.positions[i]);
            }
            for (uint32_t i : p.indices) {
                if (i >= p.positions.size())
                    throw Error("scene '" + scene.source.string() + "': mesh '" +
                                scene.meshes[mi].name + "' has an index out of range");
                idx.push_back(i);
            }
            if (r.material < 0 || r.material >= materialCount) r.material = 0;
            // Bounding sphere about the box centre with the farthest vertex's distance: tight for
            // a sphere mesh (the box's half-diagonal would be sqrt(3) x its radius), which the
            // specular scissor, the culling and the refraction exit fallback all use.
            r.center = 0.5f * (lo + hi);
            r.radius = 0.0f;
            for (const glm::vec3& q : p.positions)
                r.radius = std::max(r.radius, glm::length(q - r.center));
            meshRanges[mi].push_back(r);
        }
    }
    if (!verts.empty()) {
        vertices_ = gl::Buffer("scene vertices", verts.size() * sizeof(Vertex), verts.data(), 0);
        indices_ = gl::Buffer("scene indices", idx.size() * sizeof(uint32_t), idx.data(), 0);
        glVertexArrayVertexBuffer(vao_.id(), 0, vertices_.id(), 0, sizeof(Vertex));
        glVertexArrayElementBuffer(vao_.id(), indices_.id());
        glEnableVertexArrayAttrib(vao_.id(), 0);
        glEnableVertexArrayAttrib(vao_.id(), 1);
        glEnableVertexArrayAttrib(vao_.id(), 2);
        glVertexArrayAttribFormat(vao_.id(), 0, 3, GL_FLOAT, GL_FALSE, offsetof(Vertex, position));
        glVertexArrayAttribFormat(vao_.id(), 1, 3, GL_FLOAT, GL_FALSE, offsetof(Vertex, normal));
        glVertexArrayAttribFormat(vao_.id(), 2, 2, GL_FLOAT, GL_FALSE, offsetof(Vertex, uv));
        glVertexArrayAttribBinding(vao_.id(), 0, 0);
        glVertexArrayAttribBinding(vao_.id(), 1, 0);
        glVertexArrayAttribBinding(vao_.id(), 2, 0);
    }

    return meshRanges;
}

// Draw items of the mesh instances reachable from the scene's roots (Scene::meshInstances:
// world-from-node with the REAL/VIRTUAL flag inherited from parents), the specular ones among
// them, and the scene's bounding sphere.
void GpuScene::buildDraws(const Scene& scene, const std::vector<std::vector<Range>>& meshRanges) {
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const MeshInstance& inst : scene.meshInstances()) {
        const glm::mat4 world(inst.world);
        const std::string& nodeName = scene.nodes[size_t(inst.node)].name;
        if (!finite(world))
            throw Error("scene '" + scene.source.string() + "': node '" + nodeName +
                        "' has a non-finite transform");
        if (inst.mesh < 0 || size_t(inst.mesh) >= meshRanges.size()) {
            instanceMeshes_.push_back(-1);
            continue;
        }
        const int instanceIndex = int(instanceMeshes_.size());
        instanceMeshes_.push_back(inst.mesh);
        const float scale =
            std::max({glm::length(glm::vec3(world[0])), glm::length(glm::vec3(world[1])),
                      glm::length(glm::vec3(world[2]))});
        for (const Range& r : meshRanges[size_t(inst.mesh)]) {
            DrawItem d;
            d.name = nodeName;
            d.model = world;
            d.normalMatrix = glm::inverseTranspose(world);
            d.material = r.material;
            d.baseColorTexture = r.texture;
            d.metallicRoughnessTexture = r.metallicRoughnessTexture;
            d.origin = inst.origin;
            d.specular = r.specular;
            d.transmissive = r.transmissive;
            d.roughReflector = r.roughReflector;
            d.roughGlass = r.roughGlass;
            d.translucent = r.translucent;
            d.baseVertex = r.baseVertex;
            d.firstIndex = r.firstIndex;
            d.indexCount = r.count;
            d.bounds.center = glm::vec3(world * glm::vec4(r.center, 1.0f));
            d.bounds.radius = r.radius * scale;
            lo = glm::min(lo, d.bounds.center - glm::vec3(d.bounds.radius));
            hi = glm::max(hi, d.bounds.center + glm::vec3(d.bounds.radius));
            if (d.specular) specularDraws_.push_back(int(draws_.size()));
            draws_.push_back(d);
            localBounds_.push_back({r.center, r.radius});
            drawInstances_.push_back(instanceIndex);
        }
    }
    if (!draws_.empty()) {
        bounds_.center = 0.5f * (lo + hi);
        bounds_.radius = 0.5f * glm::length(hi - lo);
    }
}

// Lights reachable from the scene's roots (Scene::lightInstances), at most kMaxLights.
std::vector<SceneLight> GpuScene::readLights(const Scene& scene) const {
    std::vector<SceneLight> lights;
    for (const LightInstance& inst : scene.lightInstances()) {
        if (inst.light < 0 || size_t(inst.light) >= scene.lights.size()) continue;
        const Light& l = scene.lights[size_t(inst.light)];
        SceneLight s;
        s.name = l.name.empty() ? scene.nodes[size_t(inst.node)].name : l.name;
        s.type = l.type == Light::Type::Point  ? kLightPoint
                 : l.type == Light::Type::Spot ? kLightSpot
                                               : kLightDirectional;
        s.position = glm::vec3(inst.position);
        s.direction = glm::normalize(glm::vec3(inst.direction));
        s.radiantIntensity = l.color * l.intensity;
        s.range = l.range;
        const float outer = std::clamp(l.outerConeAngle, 1e-3f, 1.5707f);
        const float inner = std::clamp(l.innerConeAngle, 0.0f, outer);
        s.outerAngle = outer;
        s.cosOuter = std::cos(outer);
        s.cosInner = std::cos(inner);
        s.origin = inst.origin;
        if (lights.size() >= size_t(kMaxLights))
            throw Error("scene '" + scene.source.string() + "' has more than " +
                        std::to_string(kMaxLights) +
                        " lights; the real-time renderer supports at most that many");
        lights.push_back(s);
    }
    return lights;
}

void GpuScene::buildLights(const Scene& scene) {
    lights_ = readLights(scene);
    sceneLightCount_ = int(lights_.size());
    if (sceneLightCount_ + environmentLightSlots_ > kMaxLights)
        throw Error("scene '" + scene.source.string() + "' has " +
                    std::to_string(sceneLightCount_) + " lights; with " +
                    std::to_string(environmentLightSlots_) +
                    " found in the environment that is more than the real-time renderer's " +
                    std::to_string(kMaxLights) + "; place fewer environment lights");
}

void GpuScene::setEnvironmentLights(const std::vector<SceneLight>& lights) {
    MR_CHECK(int(lights.size()) <= environmentLightSlots_,
             "more environment lights than the renderer reserved slots for");
    lights_.resize(size_t(sceneLightCount_));
    lights_.insert(lights_.end(), lights.begin(), lights.end());
}

int GpuScene::roughReflectorCount() const {
    int n = 0;
    for (int di : specularDraws_) n += draws_[size_t(di)].roughReflector ? 1 : 0;
    return n;
}

int GpuScene::roughGlassCount() const {
    int n = 0;
    for (int di : specularDraws_) n += draws_[size_t(di)].roughGlass ? 1 : 0;
    return n;
}

// The specular draw table (GpuSpecularDraw per specular slot).
void GpuScene::uploadSpecularDraws() {
    std::vector<GpuSpecularDraw> spec;
    for (int di : specularDraws_) {
        const DrawItem& d = draws_[size_t(di)];
        GpuSpecularDraw g{};
        g.centre = d.bounds.center;
        g.radius = d.bounds.radius;
        g.material = d.material;
        g.origin = d.origin == Origin::Real ? kOriginReal : kOriginVirtual;
        g.drawIndex = di;
        g.rough = d.roughReflector ? kRoughMetal : d.roughGlass ? kRoughGlass : kRoughNone;
        spec.push_back(g);
    }
    if (spec.empty()) spec.push_back(GpuSpecularDraw{});
    const size_t bytes = spec.size() * sizeof(GpuSpecularDraw);
    if (specularBuffer_.size() == bytes)
        specularBuffer_.upload(spec.data(), bytes);  // moved objects: the same buffer
    else
        specularBuffer_ = gl::Buffer("specular draws", bytes, spec.data());
}

GpuScene::TransformUpdate GpuScene::updateTransforms(const Scene& scene) {
    const std::string what = "scene '" + scene.source.string() + "': ";
    const std::string rebuild = "; build a new renderer for another scene";
    const std::vector<MeshInstance> instances = scene.meshInstances();
    if (instances.size() != instanceMeshes_.size())
        throw Error(what + "the moved scene has " + std::to_string(instances.size()) +
                    " mesh instances, the uploaded one " + std::to_string(instanceMeshes_.size()) +
                    rebuild);
    const std::vector<SceneLight> lights = readLights(scene);
    if (int(lights.size()) != sceneLightCount_)
        throw Error(what + "the moved scene has " + std::to_string(lights.size()) +
                    " lights, the uploaded one " + std::to_string(sceneLightCount_) + rebuild);
    // Everything is checked before anything changes.
    for (size_t k = 0; k < instances.size(); ++k) {
        if (instanceMeshes_[k] < 0) continue;
        if (instances[k].mesh != instanceMeshes_[k])
            throw Error(what + "the moved scene draws other meshes than the uploaded one" +
                        rebuild);
        if (!finite(glm::mat4(instances[k].world)))
            throw Error(what + "node '" + scene.nodes[size_t(instances[k].node)].name +
                        "' has a non-finite transform");
    }
    for (size_t k = 0; k < lights.size(); ++k)
        if (lights[k].type != lights_[k].type)
            throw Error(what + "light '" + lights[k].name + "' changed its type" + rebuild);

    TransformUpdate u;
    for (size_t di = 0; di < draws_.size(); ++di)
        if (draws_[di].translucent &&
            glm::mat4(instances[size_t(drawInstances_[di])].world) != draws_[di].model)
            u.translucentMoved = true;
    if (u.translucentMoved) return u;  // nothing changed: the renderer is built anew

    glm::vec3 lo(1e30f), hi(-1e30f);
    for (size_t di = 0; di < draws_.size(); ++di) {
        DrawItem& d = draws_[di];
        const glm::mat4 world(instances[size_t(drawInstances_[di])].world);
        if (world != d.model) {
            const float scale =
                std::max({glm::length(glm::vec3(world[0])), glm::length(glm::vec3(world[1])),
                          glm::length(glm::vec3(world[2]))});
            ++u.movedDraws;
            d.model = world;
            d.normalMatrix = glm::inverseTranspose(world);
            d.bounds.center = glm::vec3(world * glm::vec4(localBounds_[di].center, 1.0f));
            d.bounds.radius = localBounds_[di].radius * scale;
        }
        lo = glm::min(lo, d.bounds.center - glm::vec3(d.bounds.radius));
        hi = glm::max(hi, d.bounds.center + glm::vec3(d.bounds.radius));
    }
    for (size_t k = 0; k < lights.size(); ++k) {
        if (lights[k].position == lights_[k].position &&
            lights[k].direction == lights_[k].direction)
            continue;
        ++u.movedLights;
        lights_[k].position = lights[k].position;
        lights_[k].direction = lights[k].direction;
    }
    if (!u.any()) return u;
    ++generation_;
    if (!draws_.empty()) {
        bounds_.center = 0.5f * (lo + hi);
        bounds_.radius = 0.5f * glm::length(hi - lo);
    }
    if (u.movedDraws == 0) return u;
    if (!specularDraws_.empty()) uploadSpecularDraws();
    if (surfacePointCount_ > 0) {
        std::vector<GpuSurfacePoint> pts(pointSources_.size());
        for (size_t k = 0; k < pts.size(); ++k) {
            const DrawItem& d = draws_[size_t(pointSources_[k].draw)];
            pts[k] = {glm::vec3(d.model * glm::vec4(pointSources_[k].local, 1.0f)),
                      d.origin == Origin::Real ? 1 : 0};
        }
        points_.upload(pts.data(), pts.size() * sizeof(GpuSurfacePoint));
    }
    return u;
}

// Surface point pool for imperfect shadow maps: area-weighted samples over all triangles
// (world space), shuffled so that any contiguous or strided subset covers the scene.
void GpuScene::buildSurfacePoints(const std::vector<Vertex>& verts,
                                  const std::vector<uint32_t>& idx, int surfacePoints) {
    std::vector<GpuSurfacePoint> pts;
    {
        struct Tri {
            glm::vec3 a, b, c;     // world
            glm::vec3 la, lb, lc;  // mesh-local
            int draw;
            float real;
        };
        std::vector<Tri> tris;
        std::vector<double> cdf;
        double total = 0.0;
        for (size_t di = 0; di < draws_.size(); ++di) {
            const DrawItem& d = draws_[di];
            for (GLsizei i = 0; i + 2 < d.indexCount; i += 3) {
                auto L = [&](GLsizei k) {
                    return verts[size_t(d.baseVertex) + idx[d.firstIndex + size_t(k)]].position;
                };
                auto P = [&](GLsizei k) { return glm::vec3(d.model * glm::vec4(L(k), 1.0f)); };
                Tri t{P(i),     P(i + 1), P(i + 2), L(i),
                      L(i + 1), L(i + 2), int(di),  d.origin == Origin::Real ? 1.0f : 0.0f};
                total += 0.5 * glm::length(glm::cross(t.b - t.a, t.c - t.a));
                tris.push_back(t);
                cdf.push_back(total);
            }
        }
        surfaceArea_ = float(total);
        if (total > 0 && surfacePoints > 0) {
            std::mt19937 rng(12345);
            std::uniform_real_distribution<float> U(0.0f, 1.0f);
            for (int i = 0; i < surfacePoints; ++i) {
                // Stratified over the area CDF so small objects still get their share.
                double target = (i + U(rng)) / surfacePoints * total;
                size_t k = size_t(std::lower_bound(cdf.begin(), cdf.end(), target) - cdf.begin());
                k = std::min(k, tris.size() - 1);
                float u = U(rng), v = U(rng);
                if (u + v > 1.0f) u = 1.0f - u, v = 1.0f - v;
                const Tri& t = tris[k];
                glm::vec3 p = t.a + u * (t.b - t.a) + v * (t.c - t.a);
                pts.push_back({p, t.real != 0.0f ? 1 : 0});
                pointSources_.push_back({t.draw, t.la + u * (t.lb - t.la) + v * (t.lc - t.la)});
                if (t.real == 0.0f) pointsHaveVirtual_ = true;
            }
            // One permutation for the points and their sources.
            std::vector<size_t> order(pts.size());
            std::iota(order.begin(), order.end(), size_t(0));
            std::shuffle(order.begin(), order.end(), rng);
            std::vector<GpuSurfacePoint> shuffled(pts.size());
            std::vector<PointSource> sources(pts.size());
            for (size_t k = 0; k < order.size(); ++k) {
                shuffled[k] = pts[order[k]];
                sources[k] = pointSources_[order[k]];
            }
            pts = std::move(shuffled);
            pointSources_ = std::move(sources);
        }
    }
    surfacePointCount_ = int(pts.size());
    if (pts.empty()) pts.push_back(GpuSurfacePoint{});
    points_ = gl::Buffer("ism surface points", pts.size() * sizeof(GpuSurfacePoint), pts.data());
}

// Environment light: SH9 for diffuse lighting and the map itself for rays that leave the scene.
void GpuScene::uploadEnvironment(const Scene& scene) {
    cv::Mat env;
    double rotationDeg = 0.0;
    if (scene.environment.kind == Environment::Kind::Equirectangular) {
        env = readLinearRgb(scene.environment.image);
        rotationDeg = scene.environment.rotationYDeg;
    } else if (scene.environment.kind == Environment::Kind::Fisheye) {
        // A fish-eye image: resampled onto an equirectangular map with the mapping and fill of
        // the live environment pass (core/camera/EquirectProjection.h, docs/environment.md), as
        // the reference renderer does.
        const CameraCalibration cal = loadCalibration(scene.environment.calibration);
        const cv::Mat frame = readLinearRgb(scene.environment.image);
        if (frame.cols != cal.intrinsics.width || frame.rows != cal.intrinsics.height)
            throw FileError(scene.environment.image.string(),
                            "the fish-eye image's size differs from its calibration " +
                                scene.environment.calibration.string());
        env = equirectFromCamera(frame, cal.intrinsics, scene.environment.T_world_camera, 1024, 512,
                                 cal.reachDeg);
    }
    if (!env.empty()) {
        envSH_ = projectEquirectToSH(env, scene.environment.intensity, rotationDeg);
        hasEnvironment_ = true;
        // The map itself, for what reflected / refracted rays see when they leave the modelled
        // scene (L_env, Knecht 2013 Sec. 4.1.3): linear RGB x intensity, RGBA16F, bilinear,
        // repeating in u (longitude), clamped in v. Large maps are halved until <= 2048 wide.
        cv::Mat m = env;
        while (m.cols > 2048)
            cv::resize(m, m, cv::Size(m.cols / 2, std::max(1, m.rows / 2)), 0, 0, cv::INTER_AREA);
        cv::Mat rgba(m.rows, m.cols, CV_32FC4);
        for (int y = 0; y < m.rows; ++y)
            for (int x = 0; x < m.cols; ++x) {
                cv::Vec3f c = m.at<cv::Vec3f>(y, x) * scene.environment.intensity;
                for (int k = 0; k < 3; ++k)
                    if (!std::isfinite(c[k]) || c[k] < 0.0f) c[k] = 0.0f;
                rgba.at<cv::Vec4f>(y, x) = cv::Vec4f(c[0], c[1], c[2], 1.0f);
            }
        envMap_ = gl::Texture::create2D("environment map", m.cols, m.rows, GL_RGBA16F);
        envMap_.upload(GL_RGBA, GL_FLOAT, rgba.data);
        glTextureParameteri(envMap_.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
        glTextureParameteri(envMap_.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        envRotationRad_ = float(rotationDeg * 3.14159265358979 / 180.0);
        environmentOrigin_ = scene.environment.origin;
    }
    if (envSH_.empty()) envSH_.assign(9, glm::vec3(0.0f));
    if (envMap_.id() == 0) {
        envMap_ = gl::Texture::create2D("environment map (none)", 1, 1, GL_RGBA16F);
        const float zero[4] = {0, 0, 0, 0};
        envMap_.upload(GL_RGBA, GL_FLOAT, zero);
    }
}

bool GpuScene::hasVirtual() const {
    for (const DrawItem& d : draws_)
        if (d.origin == Origin::Virtual) return true;
    for (const SceneLight& l : lights_)
        if (l.origin == Origin::Virtual) return true;
    return false;
}

void GpuScene::bindGeometry() const {
    vao_.bind();
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingMaterials, materials_.id());
}

void GpuScene::bindMaterialTextures(const DrawItem& d, GLuint unit) const {
    const bool has = d.baseColorTexture >= 0 && size_t(d.baseColorTexture) < textures_.size() &&
                     textures_[size_t(d.baseColorTexture)].id() != 0;
    glBindTextureUnit(unit, has ? textures_[size_t(d.baseColorTexture)].id() : white_.id());
    const int mr = d.metallicRoughnessTexture;
    const bool hasMr = mr >= 0 && size_t(mr) < textures_.size() && textures_[size_t(mr)].id() != 0;
    glBindTextureUnit(kUnitMetallicRoughnessMap, hasMr ? textures_[size_t(mr)].id() : white_.id());
}

void GpuScene::bindTableTexels(SceneTableViews& views, GLuint materialUnit,
                               GLuint specularDrawUnit) const {
    static_assert(sizeof(GpuMaterial) == 80 && sizeof(GpuSpecularDraw) == 32);
    views.materials.attachBuffer(materials_, GL_RGBA32F);
    views.specularDraws.attachBuffer(specularBuffer_, GL_RGBA32F);
    glBindTextureUnit(materialUnit, views.materials.id());
    glBindTextureUnit(specularDrawUnit, views.specularDraws.id());
}

void GpuScene::drawItem(const DrawItem& d) const {
    glDrawElementsBaseVertex(GL_TRIANGLES, d.indexCount, GL_UNSIGNED_INT,
                             reinterpret_cast<const void*>(size_t(d.firstIndex) * 4), d.baseVertex);
}

MaterialDraw::MaterialDraw(const gl::Program& program)
    : model_(program.uniformLocation("model")),
      normal_(program.uniformLocation("normalMatrix")),
      material_(program.uniformLocation("materialIndex")),
      origin_(program.uniformLocation("origin")) {}

void MaterialDraw::draw(const GpuScene& scene, const DrawItem& d) const {
    glUniformMatrix4fv(model_, 1, GL_FALSE, &d.model[0][0]);
    glUniformMatrix4fv(normal_, 1, GL_FALSE, &d.normalMatrix[0][0]);
    glUniform1i(material_, d.material);
    glUniform1i(origin_, d.origin == Origin::Real ? kOriginReal : kOriginVirtual);
    scene.bindMaterialTextures(d, kUnitBaseColorMap);
    scene.drawItem(d);
}

std::string GpuScene::lightingDefines(bool withGlass) const {
    int faces = 0;
    for (const SceneLight& l : lights_) faces = std::max(faces, l.type == kLightPoint ? 6 : 1);
    if (environmentLightSlots_ > 0) faces = std::max(faces, 1);  // directional lights
    std::string defines = "#define MIRAGE_MAX_SHADOW_FACES " + std::to_string(faces) + "\n";
    // Translucent objects use the glass atlases too (their light through them).
    if (withGlass && (hasTransmissive() || hasTranslucent()))
        defines += "#define MIRAGE_GLASS_SHADOWS 1\n";
    if (shadowPcf_) defines += "#define MIRAGE_SHADOW_PCF 1\n";
    if (!shadowPixelFootprint_) defines += "#define MIRAGE_SHADOW_NO_PIXEL_FOOTPRINT 1\n";
    return defines;
}

bool GpuScene::hasTransmissive() const {
    for (const DrawItem& d : draws_)
        if (d.transmissive) return true;
    return false;
}

bool GpuScene::hasBaseColorTextures() const {
    for (const DrawItem& d : draws_)
        if (d.baseColorTexture >= 0) return true;
    return false;
}

bool GpuScene::hasMetallicRoughnessTextures() const {
    for (const DrawItem& d : draws_)
        if (d.metallicRoughnessTexture >= 0) return true;
    return false;
}

bool GpuScene::hasTranslucent() const {
    for (const DrawItem& d : draws_)
        if (d.translucent) return true;
    return false;
}

const GpuMedium* GpuScene::medium(int material) const {
    if (material < 0 || size_t(material) >= media_.size()) return nullptr;
    const GpuMedium& m = media_[size_t(material)];
    return m.present ? &m : nullptr;
}

}  // namespace mirage::render
