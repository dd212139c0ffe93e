#include "render/passes/impostor/ImpostorPass.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>

#include "core/Error.h"
#include "core/Log.h"
#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/passes/impostor/ImpostorTypes.h"

namespace mirage::render {
namespace {

constexpr int kCoarseSamples = 8;  // linear-search samples per impostor box (trace.glsl)
constexpr float kEmptyDepth = 1e30f;

struct QueryRayGpu {
    glm::vec4 origin, direction;
};
struct QueryHitGpu {
    glm::vec4 positionHit, normalOrigin, albedoRough, emissiveMetal;
};

// Cube faces: the same table as impFaceForward / impFaceUp in trace.glsl.
const glm::vec3 kFaceForward[6] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                   {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
const glm::vec3 kFaceUp[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1},
                              {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};

void orthonormalBasis(const glm::vec3& w, glm::vec3& u, glm::vec3& v) {
    const glm::vec3 a = std::abs(w.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    u = glm::normalize(glm::cross(a, w));
    v = glm::cross(w, u);
}

// World -> clip of an impostor box: x, y, z in [-1, 1] over centre +- extent along U, V, W
// (z = -1 at the face nearest the specular object, so GL_LESS keeps the surface facing it).
glm::mat4 boxViewProj(const GpuImpostor& b, float renderExtentW) {
    glm::mat4 m(0.0f);
    const glm::vec3 c = b.centre;
    const glm::vec3 axes[3] = {b.axisU, b.axisV, b.axisW};
    const float ext[3] = {b.halfU, b.halfV, renderExtentW};
    for (int r = 0; r < 3; ++r) {
        for (int col = 0; col < 3; ++col) m[col][r] = axes[r][col] / ext[r];
        m[3][r] = -glm::dot(axes[r], c) / ext[r];
    }
    m[3][3] = 1.0f;
    return m;
}

}  // namespace

std::string ImpostorBuildStats::summary() const {
    return fmt::format(
        "{} objects: {} billboards, {} planes, {} enclosing items at {}^2; captures {:.1f} ms, "
        "build {:.1f} ms, {:.1f} MiB",
        objects, billboards, planes, enclosingItems, resolution, captureMs, wallMs,
        double(textureBytes) / (1024.0 * 1024.0));
}

ImpostorPass::ImpostorPass()
    : capture_(rasterProgram("impostor capture", "passes/impostor/capture.vert",
                             "passes/impostor/capture.frag")),
      query_(computeProgram("impostor query", "passes/impostor/query.comp")),
      captureFbo_("impostor capture fbo") {
    locViewProj_ = capture_.uniformLocation("captureViewProj");
    locCaptureDepth_ = capture_.uniformLocation("captureDepth");
    locDepthAxis_ = capture_.uniformLocation("depthAxis");
    locRayCount_ = query_.uniformLocation("rayCount");
}

namespace {
// The resources trace.glsl reads: texture units kUnitImpostorCubePosition + i, then buffers.
constexpr Resource kTracingTextures[8] = {
    kImpostorCubePosition, kImpostorCubeNormal, kImpostorCubeAlbedo, kImpostorCubeEmissive,
    kImpostorDepth,        kImpostorNormal,     kImpostorAlbedo,     kImpostorEmissive};
constexpr GLenum kTracingFormats[8] = {GL_RGBA32F, GL_RGBA16F, GL_RGBA8, GL_RGBA16F,
                                       GL_RG32F,   GL_RGBA16F, GL_RGBA8, GL_RGBA16F};
static_assert(kUnitImpostorEmissive - kUnitImpostorCubePosition == 7);
}  // namespace

void ImpostorPass::setup(PassBuilder& b) const {
    for (int i = 0; i < 8; ++i)
        b.create(kTracingTextures[i],
                 {kTracingFormats[i], SizeRule::Impostor, Storage::Persistent});
    b.createBuffer(kImpostorRecords, SizeRule::Scene, true);
    b.createBuffer(kImpostorObjects, SizeRule::Scene, true);
}

void ImpostorPass::declareTracing(PassBuilder& b) {
    for (Resource r : kTracingTextures) b.read(r);
    b.read(kImpostorRecords);
    b.read(kImpostorObjects);
}

namespace {
// trace.glsl's tables: records and objects as RGBA32F buffer textures, the header (the objects
// buffer's first bytes) as a uniform block.
void bindTables(const gl::Buffer& records, const gl::Buffer& objects,
                ImpostorPass::TableViews& views) {
    static_assert(sizeof(GpuImpostor) % 16 == 0 && sizeof(GpuImpostorObject) % 16 == 0 &&
                  sizeof(GpuImpostorHeader) == 32);
    views.records.attachBuffer(records, GL_RGBA32F);
    views.objects.attachBuffer(objects, GL_RGBA32F);
    glBindTextureUnit(kUnitImpostorRecords, views.records.id());
    glBindTextureUnit(kUnitImpostorObjects, views.objects.id());
    glBindBufferRange(GL_UNIFORM_BUFFER, kBindingImpostorHeader, objects.id(), 0,
                      sizeof(GpuImpostorHeader));
}
}  // namespace

void ImpostorPass::bindForTracing(const PassResources& res, TableViews& views) {
    for (unsigned i = 0; i < 8; ++i)
        glBindTextureUnit(kUnitImpostorCubePosition + i, res.texture(kTracingTextures[i]).id());
    bindTables(res.buffer(kImpostorRecords), res.buffer(kImpostorObjects), views);
}

PassDecision ImpostorPass::decide(const FrameContext& ctx) const {
    const size_t n = ctx.scene.specularDraws().size();
    if (n == 0) return {false, "no specular object"};
    const char* method = ctx.options.impostor.cubeMapBaseline ? "cube-map baseline" : "impostors";
    if (stale(ctx.scene, ctx.options.impostor.resolution))
        return {true, fmt::format("{} for {} specular object(s) at {}^2 ({})",
                                  builtScene_ == &ctx.scene &&
                                          builtResolution_ == ctx.options.impostor.resolution
                                      ? "rebuild (objects moved)"
                                      : "build",
                                  n, ctx.options.impostor.resolution, method)};
    return {true, fmt::format("cached ({}, {} refinement steps; built once: {})", method,
                              ctx.options.impostor.refineSteps, stats_.summary())};
}

void ImpostorPass::execute(FrameContext& ctx, PassResources& res) {
    ensureBuilt(ctx.scene, ctx.options);  // options validated with the renderer's
    const gl::Texture* textures[8] = {&cubePosition_, &cubeNormal_, &cubeAlbedo_, &cubeEmissive_,
                                      &depth_,        &normal_,     &albedo_,     &emissive_};
    for (int i = 0; i < 8; ++i) res.publish(kTracingTextures[i], *textures[i]);
    res.publish(kImpostorRecords, records_);
    res.publish(kImpostorObjects, objects_);
}

bool ImpostorPass::update(const GpuScene& scene, const RendererOptions& o) {
    if (o.impostor.resolution < 8 || o.impostor.resolution > 2048)
        throw Error(fmt::format("impostorResolution must be 8..2048 texels, got {}",
                                o.impostor.resolution));
    if (o.impostor.refineSteps < 0 || o.impostor.refineSteps > 64)
        throw Error(
            fmt::format("impostorRefineSteps must be 0..64, got {}", o.impostor.refineSteps));
    return ensureBuilt(scene, o);
}

bool ImpostorPass::ensureBuilt(const GpuScene& scene, const RendererOptions& o) {
    bool rebuilt = false;
    if (stale(scene, o.impostor.resolution)) {
        build(scene, o.impostor.resolution);
        rebuilt = true;
    }
    uploadMode(o);
    return rebuilt;
}

bool ImpostorPass::stale(const GpuScene& scene, int resolution) const {
    return builtScene_ != &scene || builtResolution_ != resolution ||
           builtGeneration_ != scene.generation();
}

void ImpostorPass::uploadMode(const RendererOptions& o) {
    GpuImpostorHeader h{};
    h.cubeMapBaseline = o.impostor.cubeMapBaseline ? 1 : 0;
    h.refinementSteps = o.impostor.refineSteps;
    h.objectCount = stats_.objects;
    h.coarseSamples = kCoarseSamples;
    h.cubeResolution = float(builtResolution_);
    h.impostorResolution = float(builtResolution_);
    std::memcpy(objectBytes_.data(), &h, sizeof(h));
    objects_.upload(objectBytes_.data(), sizeof(h));
}

// Per draw: its world points and, if all are on one plane, that plane.
struct ImpostorPass::DrawShape {
    std::vector<glm::vec3> points;
    bool planar = false;
    glm::vec3 normal{0.0f};
    glm::vec3 lo{1e30f}, hi{-1e30f};
};

// Per specular object: its impostor records (billboards, planes) and enclosing items.
struct ImpostorPass::Layout {
    std::vector<GpuImpostor> records;
    std::vector<GpuImpostorObject> objects;
    std::vector<std::vector<int>> enclosing;  // [slot]: draw indices in the enclosing cube map
};

void ImpostorPass::build(const GpuScene& scene, int res) {
    const auto wallStart = std::chrono::steady_clock::now();
    // A rebuild after objects moved happens in every frame of a drag: not worth a log line each.
    const bool moved = builtScene_ == &scene && builtResolution_ == res;
    const Layout layout = classify(scene, drawShapes(scene), res);
    allocate(scene, layout, res);
    // Captures, timed by the wall clock between two glFinish: llvmpipe's GL_TIME_ELAPSED gave
    // meaningless values for this burst of small render passes, and inside a Renderer frame the
    // pass timer is running anyway (timer queries cannot nest).
    glFinish();
    const auto captureStart = std::chrono::steady_clock::now();
    capture(scene, layout, res);
    glFinish();
    const auto end = std::chrono::steady_clock::now();
    stats_.captureMs = std::chrono::duration<double, std::milli>(end - captureStart).count();
    stats_.wallMs = std::chrono::duration<double, std::milli>(end - wallStart).count();
    if (moved)
        spdlog::debug("impostors rebuilt (objects moved): {}", stats_.summary());
    else
        spdlog::info("impostors built: {}", stats_.summary());
}

// The geometry on the CPU once (planes and tight boxes need the vertices): every draw's world
// points, box, and plane if it is planar.
std::vector<ImpostorPass::DrawShape> ImpostorPass::drawShapes(const GpuScene& scene) {
    const std::vector<DrawItem>& draws = scene.draws();
    // Mesh-local geometry never changes within a scene (moving objects changes only their
    // matrices): read back once per scene.
    std::vector<GpuSceneVertex>& verts = meshVertices_;
    std::vector<uint32_t>& indices = meshIndices_;
    if (meshesOf_ != &scene) {
        verts.assign(scene.vertexBuffer().size() / sizeof(GpuSceneVertex), GpuSceneVertex{});
        indices.assign(scene.indexBuffer().size() / sizeof(uint32_t), 0u);
        if (scene.vertexBuffer().id() != 0) {
            glGetNamedBufferSubData(scene.vertexBuffer().id(), 0,
                                    GLsizeiptr(verts.size() * sizeof(GpuSceneVertex)),
                                    verts.data());
            glGetNamedBufferSubData(scene.indexBuffer().id(), 0,
                                    GLsizeiptr(indices.size() * sizeof(uint32_t)), indices.data());
        }
        meshesOf_ = &scene;
    }
    auto worldPoints = [&](const DrawItem& d) {
        std::vector<glm::vec3> pts;
        pts.reserve(size_t(d.indexCount));
        for (GLsizei i = 0; i < d.indexCount; ++i) {
            const size_t vi = size_t(d.baseVertex) + indices[d.firstIndex + size_t(i)];
            pts.push_back(glm::vec3(d.model * glm::vec4(verts[vi].position, 1.0f)));
        }
        return pts;
    };
    std::vector<DrawShape> shapes(draws.size());
    for (size_t k = 0; k < draws.size(); ++k) {
        DrawShape& s = shapes[k];
        s.points = worldPoints(draws[k]);
        for (const glm::vec3& p : s.points) {
            s.lo = glm::min(s.lo, p);
            s.hi = glm::max(s.hi, p);
        }
        // Normal of the largest triangle, then every point within a tolerance of its plane.
        float bestArea = 0.0f;
        for (size_t i = 0; i + 2 < s.points.size(); i += 3) {
            const glm::vec3 n =
                glm::cross(s.points[i + 1] - s.points[i], s.points[i + 2] - s.points[i]);
            const float a = glm::length(n);
            if (a > bestArea && std::isfinite(a)) {
                bestArea = a;
                s.normal = n / a;
            }
        }
        if (bestArea <= 0.0f) continue;
        const float size = glm::length(s.hi - s.lo);
        const float tol = 1e-4f * size + 1e-6f;
        const float d0 = glm::dot(s.normal, s.points[0]);
        s.planar = std::all_of(s.points.begin(), s.points.end(), [&](const glm::vec3& p) {
            return std::abs(glm::dot(s.normal, p) - d0) <= tol;
        });
    }

    return shapes;
}

// Per specular object, how each other draw is represented: a billboard (the item is wholly on
// the far side of the object), a plane (planar items), or an item of the enclosing cube map.
// Fills stats_ (counts) and kinds_.
ImpostorPass::Layout ImpostorPass::classify(const GpuScene& scene,
                                            const std::vector<DrawShape>& shapes, int res) {
    const std::vector<DrawItem>& draws = scene.draws();
    const std::vector<int>& specular = scene.specularDraws();
    Layout layout;
    std::vector<GpuImpostor>& records = layout.records;
    std::vector<GpuImpostorObject>& objects = layout.objects;
    std::vector<std::vector<int>>& enclosing = layout.enclosing;
    enclosing.resize(specular.size());
    stats_ = ImpostorBuildStats{};
    kinds_.assign(specular.size(), std::vector<ItemKind>(draws.size(), ItemKind::None));
    stats_.resolution = res;
    stats_.objects = int(specular.size());
    const float margin = 1.0f + 2.0f / float(res);  // a texel of slack around every box
    for (size_t slot = 0; slot < specular.size(); ++slot) {
        const DrawItem& self = draws[size_t(specular[slot])];
        const glm::vec3 c = self.bounds.center;
        const float rS = self.bounds.radius;
        GpuImpostorObject obj{};
        obj.centre = c;
        obj.radius = rS;
        obj.firstImpostor = int(records.size());
        obj.baselineCubeLayer = int(slot) * 12;
        obj.enclosingCubeLayer = -1;
        float enclosingReach = 0.0f;
        for (size_t k = 0; k < draws.size(); ++k) {
            if (int(k) == specular[slot] || draws[k].indexCount == 0) continue;
            const DrawShape& s = shapes[k];
            if (s.points.empty()) continue;
            GpuImpostor b{};
            glm::vec3 W, U, V;
            if (s.planar) {
                W = s.normal;
                if (glm::dot(s.points[0] - c, W) < 0.0f) W = -W;
            } else {
                const glm::vec3 toItem = 0.5f * (s.lo + s.hi) - c;
                const float len = glm::length(toItem);
                W = len > 1e-6f ? toItem / len : glm::vec3(0, 0, 1);
            }
            orthonormalBasis(W, U, V);
            glm::vec3 lo(1e30f), hi(-1e30f);
            for (const glm::vec3& p : s.points) {
                const glm::vec3 q(glm::dot(p, U), glm::dot(p, V), glm::dot(p, W));
                lo = glm::min(lo, q);
                hi = glm::max(hi, q);
            }
            const glm::vec3 mid = 0.5f * (lo + hi), ext = 0.5f * (hi - lo) * margin;
            b.centre = U * mid.x + V * mid.y + W * mid.z;
            b.axisU = U, b.halfU = std::max(ext.x, 1e-5f);
            b.axisV = V, b.halfV = std::max(ext.y, 1e-5f);
            b.axisW = W, b.halfW = s.planar ? 0.0f : std::max(ext.z, 1e-5f);
            b.layer = int(records.size());
            b.kind = s.planar ? kImpostorPlane : kImpostorBillboard;
            b.drawIndex = int(k);
            if (!s.planar) {
                // A billboard is only valid when the whole item is on the far side of the object:
                // every point of the specular object must lie in front of the box's near face.
                float selfReach = -1e30f;
                for (const glm::vec3& p : shapes[size_t(specular[slot])].points)
                    selfReach = std::max(selfReach, glm::dot(p - b.centre, W));
                if (shapes[size_t(specular[slot])].points.empty())
                    selfReach = glm::dot(c - b.centre, W) + rS;
                if (selfReach > -b.halfW) {
                    enclosing[slot].push_back(int(k));
                    kinds_[slot][k] = ItemKind::Enclosing;
                    for (const glm::vec3& p : s.points)
                        enclosingReach = std::max(enclosingReach, glm::length(p - c));
                    continue;
                }
            }
            records.push_back(b);
            kinds_[slot][k] = s.planar ? ItemKind::Plane : ItemKind::Billboard;
            ++obj.impostorCount;
            (s.planar ? stats_.planes : stats_.billboards)++;
        }
        if (!enclosing[slot].empty()) {
            obj.enclosingCubeLayer = int(slot) * 12 + 6;
            obj.enclosingReach = enclosingReach + rS;
            stats_.enclosingItems += int(enclosing[slot].size());
        }
        objects.push_back(obj);
    }

    return layout;
}

// The cube-map and impostor array textures, the capture depth buffer, and the record / object
// buffers.
void ImpostorPass::allocate(const GpuScene& scene, const Layout& layout, int res) {
    const int cubeLayers = std::max(1, int(scene.specularDraws().size()) * 12);
    const int impLayers = std::max(1, int(layout.records.size()));
    GLint maxLayers = 0;
    glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &maxLayers);
    if (std::max(cubeLayers, impLayers) > maxLayers)
        throw Error(fmt::format(
            "the scene needs {} impostor layers and {} cube-map layers, but this GL allows {} "
            "array layers; merge small surrounding meshes or use fewer specular objects",
            impLayers, cubeLayers, maxLayers));
    // Objects moved within the scene: the same layers at the same resolution, re-captured.
    const bool sameSize = cubePosition_.width() == res && cubePosition_.layers() == cubeLayers &&
                          depth_.layers() == impLayers;
    if (!sameSize) allocateTextures(res, cubeLayers, impLayers);
    stats_.textureBytes = 0;
    for (const gl::Texture* t : {&cubePosition_, &cubeNormal_, &cubeAlbedo_, &cubeEmissive_,
                                 &depth_, &normal_, &albedo_, &emissive_})
        stats_.textureBytes +=
            size_t(res) * size_t(res) * size_t(t->layers()) * bytesPerTexel(t->format());

    // Records and objects (a non-empty records buffer to bind).
    const std::vector<GpuImpostor> records =
        layout.records.empty() ? std::vector<GpuImpostor>(1) : layout.records;
    records_ =
        gl::Buffer("impostor records", records.size() * sizeof(GpuImpostor), records.data(), 0);
    objectBytes_.assign(sizeof(GpuImpostorHeader) +
                            std::max<size_t>(1, layout.objects.size()) * sizeof(GpuImpostorObject),
                        0);
    if (!layout.objects.empty())
        std::memcpy(objectBytes_.data() + sizeof(GpuImpostorHeader), layout.objects.data(),
                    layout.objects.size() * sizeof(GpuImpostorObject));
    objects_ = gl::Buffer("impostor objects", objectBytes_.size(), objectBytes_.data());
    builtScene_ = &scene;
    builtResolution_ = res;
    builtGeneration_ = scene.generation();
}

void ImpostorPass::allocateTextures(int res, int cubeLayers, int impLayers) {
    cubePosition_ =
        gl::Texture::create2DArray("impostor cube position", res, res, cubeLayers, GL_RGBA32F);
    cubeNormal_ =
        gl::Texture::create2DArray("impostor cube normal", res, res, cubeLayers, GL_RGBA16F);
    cubeAlbedo_ =
        gl::Texture::create2DArray("impostor cube albedo", res, res, cubeLayers, GL_RGBA8);
    cubeEmissive_ =
        gl::Texture::create2DArray("impostor cube emissive", res, res, cubeLayers, GL_RGBA16F);
    depth_ = gl::Texture::create2DArray("impostor depth", res, res, impLayers, GL_RG32F);
    normal_ = gl::Texture::create2DArray("impostor normal", res, res, impLayers, GL_RGBA16F);
    albedo_ = gl::Texture::create2DArray("impostor albedo", res, res, impLayers, GL_RGBA8);
    emissive_ = gl::Texture::create2DArray("impostor emissive", res, res, impLayers, GL_RGBA16F);
    for (gl::Texture* t : {&cubePosition_, &cubeNormal_, &cubeAlbedo_, &cubeEmissive_, &normal_,
                           &albedo_, &emissive_})
        t->setFilter(GL_NEAREST, GL_NEAREST);
    depth_.setFilter(GL_LINEAR, GL_LINEAR);  // bilinear height field (trace.glsl impDepthAt)
    captureDepthBuffer_ =
        gl::Texture::create2D("impostor capture depth", res, res, GL_DEPTH_COMPONENT32F);
}

// Renders the cube maps (baseline and enclosing items) and every impostor.
void ImpostorPass::capture(const GpuScene& scene, const Layout& layout, int res) {
    const std::vector<DrawItem>& draws = scene.draws();
    const std::vector<int>& specular = scene.specularDraws();
    gl::Framebuffer& fbo = captureFbo_;
    glViewport(0, 0, res, res);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    capture_.use();
    scene.bindGeometry();
    auto drawOne = [&](const DrawItem& d) { captureDraw_.draw(scene, d); };
    auto target = [&](const gl::Texture& a, const gl::Texture& n, const gl::Texture& al,
                      const gl::Texture& e, int layer, const glm::vec4& clear0) {
        fbo.attachColorLayer(0, a, layer);
        fbo.attachColorLayer(1, n, layer);
        fbo.attachColorLayer(2, al, layer);
        fbo.attachColorLayer(3, e, layer);
        fbo.attachDepth(captureDepthBuffer_);
        fbo.finalize(4);
        fbo.bind();
        const float zero[4] = {0, 0, 0, 0};
        glClearBufferfv(GL_COLOR, 0, &clear0[0]);
        for (int i = 1; i < 4; ++i) glClearBufferfv(GL_COLOR, i, zero);
        const float one = 1.0f;
        glClearBufferfv(GL_DEPTH, 0, &one);
    };
    const BoundingSphere& B = scene.bounds();
    glUniform1i(locCaptureDepth_, 0);
    for (size_t slot = 0; slot < specular.size(); ++slot) {
        const glm::vec3 c = draws[size_t(specular[slot])].bounds.center;
        const float farM = glm::length(c - B.center) + B.radius + 1.0f;
        const float nearM = std::clamp(farM * 1e-5f, 1e-4f, 1e-3f);
        const glm::mat4 proj = glm::perspective(glm::half_pi<float>(), 1.0f, nearM, farM);
        for (int kind = 0; kind < 2; ++kind) {  // 0: baseline (all but self), 1: enclosing
            if (kind == 1 && layout.enclosing[slot].empty()) continue;
            for (int f = 0; f < 6; ++f) {
                target(cubePosition_, cubeNormal_, cubeAlbedo_, cubeEmissive_,
                       int(slot) * 12 + kind * 6 + f, glm::vec4(0.0f));
                const glm::mat4 vp = proj * glm::lookAt(c, c + kFaceForward[f], kFaceUp[f]);
                glUniformMatrix4fv(locViewProj_, 1, GL_FALSE, &vp[0][0]);
                if (kind == 0) {
                    for (size_t k = 0; k < draws.size(); ++k)
                        if (int(k) != specular[slot]) drawOne(draws[k]);
                } else {
                    for (int k : layout.enclosing[slot]) drawOne(draws[size_t(k)]);
                }
            }
        }
    }
    glUniform1i(locCaptureDepth_, 1);
    for (size_t slot = 0; slot < specular.size(); ++slot) {
        const GpuImpostorObject& obj = layout.objects[slot];
        for (int i = 0; i < obj.impostorCount; ++i) {
            const GpuImpostor& b = layout.records[size_t(obj.firstImpostor + i)];
            target(depth_, normal_, albedo_, emissive_, b.layer,
                   glm::vec4(kEmptyDepth, 0.0f, 0.0f, 0.0f));
            // Planar items: a thin slab around the plane (depth is only the coverage there).
            const float extW = b.kind == kImpostorPlane
                                   ? std::max(1e-4f, 1e-3f * std::max(b.halfU, b.halfV))
                                   : b.halfW;
            const glm::mat4 vp = boxViewProj(b, extW);
            glUniformMatrix4fv(locViewProj_, 1, GL_FALSE, &vp[0][0]);
            const glm::vec3 W = b.axisW;
            glUniform4f(locDepthAxis_, W.x, W.y, W.z, -glm::dot(W, b.centre));
            drawOne(draws[size_t(b.drawIndex)]);
        }
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDisable(GL_DEPTH_TEST);
}

ImpostorPass::ItemKind ImpostorPass::itemKind(int slot, int draw) const {
    if (slot < 0 || size_t(slot) >= kinds_.size() || draw < 0 ||
        size_t(draw) >= kinds_[size_t(slot)].size())
        return ItemKind::None;
    return kinds_[size_t(slot)][size_t(draw)];
}

void ImpostorPass::bindOwnForTracing() const {
    MR_CHECK(built(), "ImpostorPass::trace before the impostors were built (call update first)");
    const gl::Texture* units[8] = {&cubePosition_, &cubeNormal_, &cubeAlbedo_, &cubeEmissive_,
                                   &depth_,        &normal_,     &albedo_,     &emissive_};
    for (unsigned i = 0; i < 8; ++i)
        glBindTextureUnit(kUnitImpostorCubePosition + i, units[i]->id());
    bindTables(records_, objects_, ownViews_);
}

std::vector<ImpostorHit> ImpostorPass::trace(const std::vector<ImpostorRay>& rays) const {
    double ms = 0.0;
    return trace(rays, ms);
}

std::vector<ImpostorHit> ImpostorPass::trace(const std::vector<ImpostorRay>& rays,
                                             double& dispatchMs) const {
    dispatchMs = 0.0;
    if (rays.empty()) return {};
    std::vector<QueryRayGpu> in(rays.size());
    for (size_t i = 0; i < rays.size(); ++i)
        in[i] = {glm::vec4(rays[i].origin, float(rays[i].specularSlot)),
                 glm::vec4(rays[i].direction, 0.0f)};
    gl::Buffer rayBuf("impostor query rays", in.size() * sizeof(QueryRayGpu), in.data(), 0);
    gl::Buffer hitBuf("impostor query hits", in.size() * sizeof(QueryHitGpu), nullptr, 0);
    bindOwnForTracing();
    query_.use();
    glUniform1i(locRayCount_, int(rays.size()));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingQueryRays, rayBuf.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingQueryHits, hitBuf.id());
    // Timed by the wall clock around dispatch + glFinish: llvmpipe's GL_TIME_ELAPSED does not
    // cover compute dispatches (it reads 0 ms), and on a software rasteriser the wall clock of
    // the synchronised dispatch is the GPU time.
    glFinish();
    const auto start = std::chrono::steady_clock::now();
    glDispatchCompute(GLuint((rays.size() + 63) / 64), 1, 1);
    glFinish();
    dispatchMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<QueryHitGpu> out(rays.size());
    glGetNamedBufferSubData(hitBuf.id(), 0, GLsizeiptr(out.size() * sizeof(QueryHitGpu)),
                            out.data());
    std::vector<ImpostorHit> hits(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) {
        const QueryHitGpu& q = out[i];
        ImpostorHit& h = hits[i];
        h.hit = q.positionHit.w > 0.5f;
        h.position = glm::vec3(q.positionHit);
        h.normal = glm::vec3(q.normalOrigin);
        h.origin = int(q.normalOrigin.w + 0.5f);
        h.albedo = glm::vec3(q.albedoRough);
        h.roughness = q.albedoRough.w;
        h.emissive = glm::vec3(q.emissiveMetal);
        h.metallic = q.emissiveMetal.w;
    }
    return hits;
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeImpostorPass(const PassInit&) {
    return std::make_unique<ImpostorPass>();
}

}  // namespace mirage::render
