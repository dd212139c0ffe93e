#pragma once
// Reflected-scene impostors for specular objects (Knecht 2013 Sec. 3.2, Popescu et al.
// 2006): per specular object (GpuScene::specularDraws()), the data that
// render/passes/impostor/trace.glsl's traceSurroundings() needs to find where a reflected or
// refracted ray leaving the object hits its surroundings:
//  - a G-buffer cube map of the scene minus the object, from the object's bounding-sphere centre
//    (the plain cube-map baseline, looked up by direction only);
//  - one depth impostor per surrounding draw item: an orthographic box around the item whose W
//    axis points away from the specular object's centre, storing per texel the surface's offset
//    along W (a height field relative to the billboard plane) and its G-buffer attributes; planar
//    items get an impostor lying in their own plane (exact ray-plane intersection);
//  - a G-buffer cube map of the items that enclose the object or reach behind their billboard's
//    near face as seen from it (a room, a large non-planar table), searched along the ray.
// Everything is built once (the frame it happens, the report says "build ...", with its GPU time
// in the pass timer) and cached while nothing moves; it is rebuilt in the frame after objects
// moved (GpuScene::generation(), "rebuild (objects moved)") or when
// RendererOptions::impostor.resolution changes. Refinement steps and
// the baseline switch are per-frame uniforms (no rebuild). World = glTF frame (metres, +Y up).
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "render/GpuScene.h"
#include "render/RenderPass.h"

namespace mirage::render {

// Reflected-scene impostors of the specular objects' surroundings (persistent: built once per
// scene; trace.glsl reads them): G-buffer cube maps (12 layers per specular object), depth
// impostors (one layer each), and their tables.
inline constexpr Resource kImpostorCubePosition{"ImpostorCubePosition"};
inline constexpr Resource kImpostorCubeNormal{"ImpostorCubeNormal"};
inline constexpr Resource kImpostorCubeAlbedo{"ImpostorCubeAlbedo"};
inline constexpr Resource kImpostorCubeEmissive{"ImpostorCubeEmissive"};
inline constexpr Resource kImpostorDepth{"ImpostorDepth"};
inline constexpr Resource kImpostorNormal{"ImpostorNormal"};
inline constexpr Resource kImpostorAlbedo{"ImpostorAlbedo"};
inline constexpr Resource kImpostorEmissive{"ImpostorEmissive"};
inline constexpr Resource kImpostorRecords{"ImpostorRecords"};  // SSBO of GpuImpostor
// SSBO: header + GpuImpostorObject per specular object.
inline constexpr Resource kImpostorObjects{"ImpostorObjects"};

// A ray for the offline query (tests, accuracy benchmark): world, metres; direction unit.
struct ImpostorRay {
    glm::vec3 origin{0.0f};
    glm::vec3 direction{0.0f, 0.0f, 1.0f};
    int specularSlot = 0;  // index into GpuScene::specularDraws() of the object the ray leaves
};

// What traceSurroundings() returned for one ray (the GLSL SurroundingHit).
struct ImpostorHit {
    bool hit = false;          // false: the ray leaves the modelled scene
    glm::vec3 position{0.0f};  // world (m)
    glm::vec3 normal{0.0f};    // unit, facing the ray origin
    glm::vec3 albedo{0.0f};    // linear
    glm::vec3 emissive{0.0f};  // linear radiance
    float roughness = 1.0f, metallic = 0.0f;
    int origin = kOriginNone;  // kOriginReal / kOriginVirtual
};

struct ImpostorBuildStats {
    int resolution = 0;       // texels per side of each impostor and cube face
    int objects = 0;          // specular objects
    int billboards = 0;       // depth impostors (all objects)
    int planes = 0;           // planar-item impostors (all objects)
    int enclosingItems = 0;   // (object, item) pairs in the enclosing cube maps
    double captureMs = 0.0;   // rendering the cube maps + impostors (wall clock between glFinish)
    double wallMs = 0.0;      // the whole build: geometry readback, classification, allocation,
                              // captures (wall clock)
    size_t textureBytes = 0;  // GPU memory of all impostor and cube-map textures
    std::string summary() const;
};

class ImpostorPass final : public RenderPass {
public:
    ImpostorPass();
    const char* name() const override { return "impostor"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext&) override {}
    void execute(FrameContext& ctx, PassResources& res) override;

    // The record and object tables as the buffer textures trace.glsl reads them through. Each
    // tracing pass owns a set: a buffer texture only points at a buffer, and bindForTracing
    // points it again every frame (the impostors are rebuilt when the scene changes).
    struct TableViews {
        gl::Texture records = gl::Texture::createBufferView("impostor records (texels)");
        gl::Texture objects = gl::Texture::createBufferView("impostor objects (texels)");
    };
    // For a pass that traces the surroundings with trace.glsl: declares the impostor resources
    // as its reads, and binds them by name (texture units kUnitImpostor* and the uniform block
    // kBindingImpostorHeader, render/bindings.glsl).
    static void declareTracing(PassBuilder& b);
    static void bindForTracing(const PassResources& res, TableViews& views);

    // Builds the impostors if the scene (by address) or the resolution changed (returns true
    // then), and sets the per-frame mode (refinement steps, baseline). Throws mirage::Error on
    // bad options or when the scene needs more array layers than the GL allows.
    bool update(const GpuScene& scene, const RendererOptions& options);
    bool built() const { return builtScene_ != nullptr; }
    const ImpostorBuildStats& buildStats() const { return stats_; }
    // How draw `draw` is represented for specular object `slot` (None: itself, or not built).
    enum class ItemKind { None, Billboard, Plane, Enclosing };
    ItemKind itemKind(int slot, int draw) const;

    // Offline: traces `rays` with traceSurroundings() in a compute shader and reads the hits back
    // (blocks). For tests and the accuracy benchmark; needs update() first.
    std::vector<ImpostorHit> trace(const std::vector<ImpostorRay>& rays) const;
    // The same, timed: milliseconds of the dispatch alone (wall clock of dispatch + glFinish;
    // llvmpipe's timer queries do not cover compute).
    std::vector<ImpostorHit> trace(const std::vector<ImpostorRay>& rays, double& dispatchMs) const;

private:
    struct DrawShape;
    struct Layout;
    // build(): drawShapes -> classify -> allocate -> capture.
    void build(const GpuScene& scene, int resolution);
    std::vector<DrawShape> drawShapes(const GpuScene& scene);
    Layout classify(const GpuScene& scene, const std::vector<DrawShape>& shapes, int resolution);
    void allocate(const GpuScene& scene, const Layout& layout, int resolution);
    void capture(const GpuScene& scene, const Layout& layout, int resolution);
    void uploadMode(const RendererOptions& options);
    // True when the captures are not of this scene as it stands now at this resolution (another
    // scene, its objects moved, another resolution).
    bool stale(const GpuScene& scene, int resolution) const;
    // The cube-map and impostor arrays and the capture depth buffer.
    void allocateTextures(int res, int cubeLayers, int impLayers);
    // Builds if the scene or resolution changed (options already validated).
    bool ensureBuilt(const GpuScene& scene, const RendererOptions& options);
    // Binds the impostors of this pass for the offline query.
    void bindOwnForTracing() const;

    gl::Program capture_, query_;
    MaterialDraw captureDraw_{capture_};  // after capture_
    GLint locViewProj_ = -1, locCaptureDepth_ = -1, locDepthAxis_ = -1, locRayCount_ = -1;
    // Cube maps: 12 layers per specular object (6 baseline faces, 6 enclosing-items faces).
    gl::Texture cubePosition_, cubeNormal_, cubeAlbedo_, cubeEmissive_;
    // Impostors: one layer each.
    gl::Texture depth_, normal_, albedo_, emissive_;
    gl::Texture captureDepthBuffer_;
    gl::Buffer records_, objects_;
    mutable TableViews ownViews_;             // bindOwnForTracing's (the offline queries)
    std::vector<unsigned char> objectBytes_;  // header + objects, re-uploaded with the mode
    gl::Framebuffer captureFbo_;
    const GpuScene* builtScene_ = nullptr;
    int builtResolution_ = 0;
    uint64_t builtGeneration_ = 0;  // GpuScene::generation() the captures show
    // The scene's mesh-local vertices and indices, read back once per scene (meshesOf_).
    const GpuScene* meshesOf_ = nullptr;
    std::vector<GpuSceneVertex> meshVertices_;
    std::vector<uint32_t> meshIndices_;
    ImpostorBuildStats stats_;
    std::vector<std::vector<ItemKind>> kinds_;  // [slot][draw]
};

}  // namespace mirage::render
