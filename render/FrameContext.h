#pragma once
// Everything one frame's passes share: the scene on the GPU, the camera (intrinsics + pose),
// the per-frame plan (which lights cast shadows, which need a real-only shadow map, whether
// VPLs are needed), the uniform buffers, and the frame's resources as published by the passes
// that wrote them (a pass may only read what an earlier pass published or what was imported).
#include <array>
#include <map>
#include <string>
#include <vector>

#include "core/gl/Objects.h"
#include "core/math/Pose.h"
#include "render/CameraProjection.h"
#include "render/GpuScene.h"
#include "render/GpuTypes.h"

namespace mirage::render {

// Frame resources. Buffers named L_* are linear HDR radiance (RGBA16F, rgb used).
enum class Resource {
    CameraImage,     // imported: the camera frame, sRGB8 texture sampled as linear (image size)
    GBuffer,         // position/origin, normal/roughness, albedo/metallic, depth (canvas size)
    ShadowMaps,      // per light layer: distance to the nearest occluder (all geometry)
    ShadowMapsReal,  // the same with real occluders only (only for lights that need it)
    ReflectiveShadowMaps,     // per light layer: flux/origin, normal, position (for VPLs)
    Vpls,                     // SSBO of GpuVpl
    ImperfectShadowMaps,      // r32ui atlas, one paraboloid tile per VPL (all occluders)
    ImperfectShadowMapsReal,  // the same with real points only
    DirectRv,
    DirectR,  // direct + environment + emission, routed (canvas size)
    IndirectRv,
    IndirectR,  // interleaved VPL gather, unfiltered (canvas size)
    LRv,
    LR,  // the two GI solutions, filtered and temporally smoothed
    // Specular objects (issue 6, Knecht 2013 Sec. 4.1 / 5.1; docs/specular.md):
    BackFaces,          // specular objects' back faces: world position + slot, normal (canvas)
    RealSurfaces,       // nearest REAL surface per pixel (world position + origin), canvas size
    ReflectionGBuffer,  // GBuf_refl: reflected-ray hits (position/origin, normal, albedo, ...)
    RefractionGBuffer,  // GBuf_refr: two-interface refracted-ray hits (Wyman 2005)
    SpecularRv,         // L'_rv (Eq. 3), Fresnel-weighted, canvas size
    SpecularR,          // L'_r (Eq. 4)
    Lenv,               // L_env: environment seen where a ray leaves the modelled scene
    Composite,          // final image (camera image size): linear RGBA32F + sRGB8
    Impostors,  // per specular object: reflected-scene impostors + G-buffer cube maps (world)
};
const char* resourceName(Resource r);

struct RendererOptions {
    int vplCount = 256;                  // total VPLs per frame, split over the lights with RSMs
    int shadowMapSize = 512;             // texels per side of each shadow / RSM layer
    int ismTileSize = 64;                // texels per side of one VPL's imperfect shadow map
    int ismPointsPerVpl = 1024;          // surface points splatted into each VPL's ISM
    int interleave = 4;                  // K: each pixel gathers vplCount / K^2 VPLs
    int indirectScale = 2;               // VPL gather at 1/scale resolution per axis (1 or 2); the
                                         // geometry-aware filter upsamples it to full resolution
    float vplDistanceClamp = 0.1f;       // metres: VPL distance below this is clamped (no spikes)
    float shadowBias = 0.01f;            // metres, at 1 m distance (scaled with distance)
    float temporalBlend = 0.8f;          // history weight for the VPL lighting (0 = off)
    float exposure = 1.0f;               // rendered linear radiance -> camera linear units
    float alphaMax = 8.0f;               // cap of alpha = CI / L_r
    float alphaFadeLr = 0.02f;           // where L_r (linear) is below this, alpha fades to 1
    float nearM = 0.01f, farM = 100.0f;  // camera clip planes (metres)
    // Specular objects (docs/specular.md).
    int refractionMarchSteps = 16;        // back-face depth march steps of the refracted ray
    float backProjectionEpsilon = 0.02f;  // depth validation: |d - d_gbuf| < eps * d + 0.005 m
    bool specularVpls = true;             // light GBuf_refl / GBuf_refr hits with the VPLs too
    int specularVplStride = 4;  // 1, 4 or 16: each hit sums every stride-th VPL (x stride),
                                // interleaved over 2x2 / 4x4 pixels (cheaper, noisier)
    // Reuse the camera-independent passes' output (shadow maps, RSMs, VPLs, ISMs) while the
    // frame plan is unchanged, instead of re-rendering it every frame (false: always re-run).
    bool reuseStaticPasses = true;
    bool cullPasses = true;  // run only the passes the scene needs (false: run all; tests)
    // glFinish around every pass so each timer query holds only its pass's work. llvmpipe defers
    // rasterisation until a later sync (a compute dispatch that reads the result, a readback), so
    // without this a pass's time can show up in the next pass's query. For benchmarks.
    bool syncPasses = false;

    // Reflected-scene impostors for specular objects (render/passes/impostor, issue 6).
    int impostorResolution = 256;          // texels per side of each impostor and cube face
    int impostorRefineSteps = 4;           // secant refinement steps of the height-field search
    bool impostorCubeMapBaseline = false;  // true: plain G-buffer cube map, looked up by direction
};

struct LightPlan {
    bool castsShadow = false;        // some caster inside the light's cone
    bool needsRealOnlyMap = false;   // a virtual caster in the cone of a REAL light
    bool reachesVirtual = false;     // a virtual object inside the light's cone
    bool hasRsm = false;             // VPLs are placed from this light
    int firstLayer = 0, layers = 0;  // in the shadow / RSM atlases
    int firstVpl = 0, vplCount = 0;
    std::string reason;
};

struct FramePlan {
    std::vector<LightPlan> lights;
    int shadowLayers = 0;
    bool needVpls = false;
    bool needRealOnlyShadows = false;
    bool needRealOnlyIsm = false;
    std::string vplReason;
};

class FrameContext {
public:
    FrameContext(const GpuScene& scene, const CameraProjection& projection,
                 const RendererOptions& options);

    const GpuScene& scene;
    const CameraProjection& projection;
    const RendererOptions& options;

    Pose T_world_camera;  // OpenCV camera axes
    FramePlan plan;
    GpuFrame frame{};  // uploaded to the FrameBlock UBO before the passes run
    GpuLightBlock lightBlock{};
    int frameIndex = 0;
    bool historyValid = false;

    gl::Buffer frameUbo, lightUbo;
    gl::VertexArray emptyVao;  // for full-screen triangles

    void publish(Resource r, const gl::Texture* tex);  // tex may be null for buffer resources
    bool has(Resource r) const { return published_.count(r) != 0; }
    const gl::Texture& texture(Resource r) const;  // throws (a bug) if not published
    void clearResources() { published_.clear(); }

    const gl::Texture& blackTexture() const { return black_; }          // 1x1 RGBA16F zero
    const gl::Texture& farShadowTexture() const { return farShadow_; }  // 1x1 array, 1e30

    int canvasWidth() const { return projection.canvasWidth; }
    int canvasHeight() const { return projection.canvasHeight; }
    void bindFrameBlocks() const;
    // Full-screen pass set-up: viewport width x height, depth test and blending off, `program`
    // in use and the frame's uniform blocks bound (the pass binds its framebuffer first).
    void beginFullscreen(const gl::Program& program, int width, int height) const;
    // The full-screen triangle of fullscreen.vert (no vertex data: emptyVao).
    void drawFullscreenTriangle() const;

private:
    std::map<Resource, const gl::Texture*> published_;
    gl::Texture black_, farShadow_;
};

}  // namespace mirage::render
