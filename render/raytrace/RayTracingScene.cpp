#include "render/raytrace/RayTracingScene.h"

#include <array>
#include <cmath>

#include <fmt/format.h>

#include "core/Error.h"
#include "core/camera/CalibrationFile.h"
#include "core/camera/EquirectProjection.h"
#include "core/image/ImageIO.h"

namespace mirage::raytrace {
namespace {

// sRGB byte -> linear float, tabulated once.
const std::array<float, 256>& srgbTable() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[size_t(i)] = srgbToLinear(float(i) / 255.0f);
        return t;
    }();
    return table;
}

// Offset for rays leaving a surface: large enough to escape float round-off at the hit, small
// enough not to skip thin geometry (scenes are metres, ~0.1 mm).
float rayEpsilon(const glm::vec3& p) {
    return 1e-4f * std::max(1.0f, std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z))));
}

RTCRay makeRay(const glm::vec3& o, const glm::vec3& d, float tMax) {
    RTCRay r{};
    r.org_x = o.x;
    r.org_y = o.y;
    r.org_z = o.z;
    r.dir_x = d.x;
    r.dir_y = d.y;
    r.dir_z = d.z;
    r.tnear = rayEpsilon(o) / std::max(1e-20f, glm::length(d));
    r.tfar = tMax;
    r.mask = 0xFFFFFFFFu;
    r.flags = 0;
    r.time = 0;
    return r;
}

}  // namespace

float PunctualLight::spotFactor(float cosAngle) const {
    if (type != Light::Type::Spot) return 1.0f;
    float scale = 1.0f / std::max(1e-3f, cosInner - cosOuter);
    float a = std::clamp((cosAngle - cosOuter) * scale, 0.0f, 1.0f);
    return a * a;
}

RayTracingScene::RayTracingScene(const Scene& scene, SceneSubset subset, const EmbreeDevice& device)
    : device_(&device), scene_(device), subset_(subset), textures_(scene.textures) {
    auto included = [&](Origin o) { return subset == SceneSubset::All || o == Origin::Real; };

    // Materials: the scene's, then the glTF default material (used for index -1).
    materials_.reserve(scene.materials.size() + 1);
    auto addMaterial = [&](const Material& m) {
        ShadingMaterial sm;
        sm.gltf = m;
        if (std::isfinite(m.attenuationDistance) && m.attenuationDistance > 0) {
            for (int k = 0; k < 3; ++k)
                sm.sigmaA[k] = -std::log(std::clamp(m.attenuationColor[k], 1e-6f, 1.0f)) /
                               m.attenuationDistance;
            sm.hasVolume = sm.sigmaA != glm::vec3(0.0f);
        }
        for (const TextureRef* ref : {&m.baseColorTexture, &m.emissiveTexture})
            if (ref->valid() && ref->texture >= int(textures_.size()))
                throw Error("scene material '" + m.name + "': texture index " +
                            std::to_string(ref->texture) + " out of range (" +
                            std::to_string(textures_.size()) + " textures)");
        materials_.push_back(sm);
    };
    for (const auto& m : scene.materials) addMaterial(m);
    addMaterial(Material{});
    for (const auto& t : textures_)
        if (t.width <= 0 || t.height <= 0 || t.pixels.size() < size_t(t.width) * t.height * 4)
            throw Error("scene texture '" + t.name + "': pixel data does not match its size " +
                        std::to_string(t.width) + "x" + std::to_string(t.height) + " RGBA8");

    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    // Lights and meshes reachable from the scene's roots, with world transforms and origins.
    addLights(scene);
    for (const MeshInstance& mi : scene.meshInstances()) {
        if (!included(mi.origin)) continue;
        const Node& node = scene.nodes[size_t(mi.node)];
        if (mi.mesh < 0 || mi.mesh >= int(scene.meshes.size()))
            throw Error("scene node '" + node.name + "': mesh index out of range");
        const Mesh& mesh = scene.meshes[size_t(mi.mesh)];
        glm::dmat4 world = mi.world;
        glm::dmat3 normalMatrix = glm::transpose(glm::inverse(glm::dmat3(world)));
        bool flipWinding = glm::determinant(glm::dmat3(world)) < 0;
        for (const Primitive& prim : mesh.primitives) {
            const std::string where = "scene mesh '" + mesh.name + "' (node '" + node.name + "')";
            if (prim.indices.size() % 3 != 0)
                throw Error(where + ": index count is not a multiple of 3");
            if (prim.indices.empty()) continue;
            Geometry g;
            g.origin = mi.origin;
            g.material = prim.material >= 0 ? prim.material : int(materials_.size()) - 1;
            if (g.material >= int(materials_.size()))
                throw Error(where + ": material index " + std::to_string(prim.material) +
                            " out of range");
            size_t nv = prim.positions.size();
            for (uint32_t i : prim.indices)
                if (i >= nv)
                    throw Error(where + ": vertex index " + std::to_string(i) + " out of range");
            g.positions.resize(nv);
            for (size_t i = 0; i < nv; ++i) {
                g.positions[i] = glm::vec3(world * glm::dvec4(prim.positions[i], 1.0));
                if (!isFiniteVec(g.positions[i]))
                    throw Error(where + ": non-finite vertex position");
                lo = glm::min(lo, g.positions[i]);
                hi = glm::max(hi, g.positions[i]);
            }
            if (prim.normals.size() == nv) {
                g.normals.resize(nv);
                for (size_t i = 0; i < nv; ++i) {
                    glm::dvec3 n = normalMatrix * glm::dvec3(prim.normals[i]);
                    double len = glm::length(n);
                    g.normals[i] =
                        len > 0 && std::isfinite(len) ? glm::vec3(n / len) : glm::vec3(0.0f);
                }
            }
            if (prim.uv0.size() == nv) g.uv0 = prim.uv0;
            if (prim.uv1.size() == nv) g.uv1 = prim.uv1;
            g.indices = prim.indices;
            if (flipWinding)
                for (size_t i = 0; i < g.indices.size(); i += 3)
                    std::swap(g.indices[i + 1], g.indices[i + 2]);
            const Material& mat = materials_[size_t(g.material)].gltf;
            Bsdf probe(BsdfParams{glm::vec3(mat.baseColor), mat.metallic, mat.roughness, mat.ior,
                                  mat.transmission, mat.isMirror()});
            g.deltaSpecular = probe.hasDelta() && !mat.isTranslucent();
            if (mat.isTranslucent()) {
                Medium md;
                md.extinction = mat.scattering.extinction;
                md.albedo = mat.scattering.albedo;
                md.density = mat.scattering.density;
                md.localFromWorld = glm::mat4(glm::inverse(world));
                md.ior = mat.ior;
                md.majorant = md.extinction * (md.density ? md.density->maxValue : 1.0f);
                if (!std::isfinite(md.majorant) || !isFiniteVec(md.albedo) ||
                    !(glm::determinant(glm::dmat3(world)) != 0))
                    throw Error(where + ": translucent material '" + mat.name +
                                "' has a non-finite extinction or a singular transform");
                g.medium = int(media_.size());
                media_.push_back(std::move(md));
            }
            glm::vec3 glo(std::numeric_limits<float>::max()),
                ghi(-std::numeric_limits<float>::max());
            for (const auto& p : g.positions) {
                glo = glm::min(glo, p);
                ghi = glm::max(ghi, p);
            }
            g.bounds.centre = 0.5f * (glo + ghi);
            for (const auto& p : g.positions)
                g.bounds.radius = std::max(g.bounds.radius, glm::length(p - g.bounds.centre));

            attach(std::move(g));
        }
    }
    rtcSetSceneBuildQuality(scene_.get(), RTC_BUILD_QUALITY_HIGH);
    rtcCommitScene(scene_.get());
    device.throwIfError("rtcCommitScene");
    if (!geometries_.empty()) {
        sceneBounds_.centre = 0.5f * (lo + hi);
        sceneBounds_.radius = 0.5f * glm::length(hi - lo);
    }

    const Environment& env = scene.environment;
    if (env.kind != Environment::Kind::None && included(env.origin)) loadEnvironment(env);
}

// The scene's punctual lights reachable from its roots (the subset's), in world space.
void RayTracingScene::addLights(const Scene& scene) {
    auto included = [&](Origin o) { return subset_ == SceneSubset::All || o == Origin::Real; };
    for (const LightInstance& li : scene.lightInstances()) {
        if (!included(li.origin)) continue;
        const Node& node = scene.nodes[size_t(li.node)];
        if (li.light < 0 || li.light >= int(scene.lights.size()))
            throw Error("scene node '" + node.name + "': light index out of range");
        const Light& l = scene.lights[size_t(li.light)];
        PunctualLight pl;
        pl.type = l.type;
        pl.position = glm::vec3(li.position);
        if (!(glm::length(li.direction) > 0))
            throw Error("scene node '" + node.name + "': degenerate light transform");
        pl.direction = glm::vec3(glm::normalize(li.direction));
        pl.intensity = l.color * l.intensity;
        pl.cosInner = std::cos(std::clamp(l.innerConeAngle, 0.0f, kPi / 2));
        pl.cosOuter = std::cos(std::clamp(l.outerConeAngle, 0.0f, kPi / 2));
        pl.origin = li.origin;
        if (!isFiniteVec(pl.position) || !isFiniteVec(pl.intensity) ||
            std::min(pl.intensity.x, std::min(pl.intensity.y, pl.intensity.z)) < 0)
            throw Error("scene light '" + l.name + "': non-finite or negative position/intensity");
        lights_.push_back(pl);
    }
}

// Uploads a geometry's triangles to Embree; its Embree id is its index in geometries_.
void RayTracingScene::attach(Geometry g) {
    RTCGeometry geom = rtcNewGeometry(device_->get(), RTC_GEOMETRY_TYPE_TRIANGLE);
    device_->throwIfError("rtcNewGeometry");
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), g.positions.size()));
    auto* ib = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(uint32_t), g.indices.size() / 3));
    device_->throwIfError("rtcSetNewGeometryBuffer");
    for (size_t i = 0; i < g.positions.size(); ++i) {
        vb[3 * i] = g.positions[i].x;
        vb[3 * i + 1] = g.positions[i].y;
        vb[3 * i + 2] = g.positions[i].z;
    }
    std::copy(g.indices.begin(), g.indices.end(), ib);
    rtcCommitGeometry(geom);
    unsigned id = rtcAttachGeometry(scene_.get(), geom);
    rtcReleaseGeometry(geom);
    device_->throwIfError("rtcAttachGeometry");
    MR_CHECK(id == geometries_.size(), "Embree geometry ids are expected to be dense");
    geometries_.push_back(std::move(g));
}

// The scene's environment map (an equirectangular image, or a fish-eye camera frame resampled
// onto one).
void RayTracingScene::loadEnvironment(const Environment& env) {
    if (env.kind == Environment::Kind::Fisheye) {
        // The camera frame resampled onto an equirectangular map exactly as the real-time
        // renderer's environment pass does (core/camera/EquirectProjection.h: same
        // directions, same fill of the unseen part), so ground truth exists for it.
        const CameraCalibration cal = loadCalibration(env.calibration);
        const cv::Mat frame = readLinearRgb(env.image);
        if (frame.cols != cal.intrinsics.width || frame.rows != cal.intrinsics.height)
            throw FileError(env.image.string(),
                            fmt::format("the fish-eye image is {}x{}, but its calibration {} "
                                        "is for {}x{}",
                                        frame.cols, frame.rows, env.calibration.string(),
                                        cal.intrinsics.width, cal.intrinsics.height));
        const cv::Mat map =
            equirectFromCamera(frame, cal.intrinsics, env.T_world_camera, kFisheyeEnvironmentWidth,
                               kFisheyeEnvironmentWidth / 2, cal.reachDeg);
        environment_ = std::make_unique<EnvironmentLight>(map, env.intensity, 0.0);
    } else {
        cv::Mat img = readLinearRgb(env.image);
        environment_ = std::make_unique<EnvironmentLight>(img, env.intensity, env.rotationYDeg);
    }
}

void RayTracingScene::setEnvironment(std::unique_ptr<EnvironmentLight> environment) {
    environment_ = std::move(environment);
}

bool RayTracingScene::intersect(const glm::vec3& o, const glm::vec3& d, float tMax,
                                SurfaceHit& hit) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh{};
    rh.ray = makeRay(o, d, tMax);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_.get(), &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    const Geometry& g = geometries_[rh.hit.geomID];
    uint32_t i0 = g.indices[3 * rh.hit.primID], i1 = g.indices[3 * rh.hit.primID + 1],
             i2 = g.indices[3 * rh.hit.primID + 2];
    float b1 = rh.hit.u, b2 = rh.hit.v, b0 = 1.0f - b1 - b2;
    hit.t = rh.ray.tfar;
    hit.geometry = rh.hit.geomID;
    hit.p = b0 * g.positions[i0] + b1 * g.positions[i1] + b2 * g.positions[i2];
    glm::vec3 ng = glm::cross(g.positions[i1] - g.positions[i0], g.positions[i2] - g.positions[i0]);
    float len = glm::length(ng);
    hit.ng = len > 0 ? ng / len : -glm::normalize(d);
    hit.ns = hit.ng;
    if (!g.normals.empty()) {
        glm::vec3 ns = b0 * g.normals[i0] + b1 * g.normals[i1] + b2 * g.normals[i2];
        float l = glm::length(ns);
        if (l > 1e-6f) {
            ns /= l;
            hit.ns = glm::dot(ns, hit.ng) < 0 ? -ns : ns;
        }
    }
    hit.uv[0] = g.uv0.empty() ? glm::vec2(0.0f) : b0 * g.uv0[i0] + b1 * g.uv0[i1] + b2 * g.uv0[i2];
    hit.uv[1] = g.uv1.empty() ? glm::vec2(0.0f) : b0 * g.uv1[i0] + b1 * g.uv1[i1] + b2 * g.uv1[i2];
    return true;
}

bool RayTracingScene::occluded(const glm::vec3& o, const glm::vec3& d, float tMax) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r = makeRay(o, d, tMax);
    rtcOccluded1(scene_.get(), &ctx, &r);
    return r.tfar < 0.0f;  // Embree sets tfar = -inf on a hit
}

const ShadingMaterial& RayTracingScene::material(const SurfaceHit& hit) const {
    return materials_[size_t(geometries_[hit.geometry].material)];
}

glm::vec3 RayTracingScene::sampleTexture(int texture, glm::vec2 uv) const {
    // Bilinear with the glTF sampler's wrap modes; sRGB-encoded texels are decoded before
    // filtering.
    const Texture& t = textures_[size_t(texture)];
    float x = uv.x * float(t.width) - 0.5f, y = uv.y * float(t.height) - 0.5f;
    if (!std::isfinite(x) || !std::isfinite(y)) return glm::vec3(1.0f);
    float fx = std::floor(x), fy = std::floor(y);
    float ax = x - fx, ay = y - fy;
    auto wrap = [](long v, int n, Texture::Wrap mode) {
        switch (mode) {
            case Texture::Wrap::ClampToEdge:
                return int(std::clamp<long>(v, 0, n - 1));
            case Texture::Wrap::MirroredRepeat: {
                long period = 2L * n, m = ((v % period) + period) % period;
                return int(m < n ? m : period - 1 - m);
            }
            case Texture::Wrap::Repeat:
                break;
        }
        return int(((v % n) + n) % n);
    };
    const auto& lut = srgbTable();
    glm::vec3 out(0.0f);
    for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
            int px = wrap(long(fx) + dx, t.width, t.wrapS),
                py = wrap(long(fy) + dy, t.height, t.wrapT);
            const unsigned char* c = &t.pixels[(size_t(py) * size_t(t.width) + size_t(px)) * 4];
            float w = (dx ? ax : 1 - ax) * (dy ? ay : 1 - ay);
            out += w * (t.srgb ? glm::vec3(lut[c[0]], lut[c[1]], lut[c[2]])
                               : glm::vec3(c[0], c[1], c[2]) / 255.0f);
        }
    return out;
}

BsdfParams RayTracingScene::bsdfParams(const SurfaceHit& hit) const {
    const Material& m = material(hit).gltf;
    BsdfParams p;
    p.baseColor = glm::vec3(m.baseColor);
    if (m.baseColorTexture.valid())
        p.baseColor *= sampleTexture(m.baseColorTexture.texture,
                                     hit.uv[m.baseColorTexture.texCoord == 1 ? 1 : 0]);
    p.metallic = m.metallic;
    p.roughness = m.roughness;
    p.ior = m.ior;
    p.transmission = m.transmission;
    p.mirror = m.isMirror();
    return p;
}

glm::vec3 RayTracingScene::emission(const SurfaceHit& hit) const {
    const Material& m = material(hit).gltf;
    glm::vec3 e = m.emissive;
    if (e == glm::vec3(0.0f)) return e;
    if (m.emissiveTexture.valid())
        e *= sampleTexture(m.emissiveTexture.texture,
                           hit.uv[m.emissiveTexture.texCoord == 1 ? 1 : 0]);
    return e;
}

std::vector<RayTracingScene::BoundingSphere> RayTracingScene::deltaSpecularBounds() const {
    std::vector<BoundingSphere> out;
    for (const auto& g : geometries_)
        if (g.deltaSpecular) out.push_back(g.bounds);
    return out;
}

}  // namespace mirage::raytrace
