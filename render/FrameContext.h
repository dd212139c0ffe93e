#pragma once
// Everything one frame's passes share: the scene on the GPU, the camera (intrinsics + pose),
// the per-frame plan (which lights cast shadows, which need a real-only shadow map, whether
// VPLs are needed) and the uniform buffers. The frame's textures are handed from pass to pass by
// the frame graph (render/FrameGraph.h), not through this context.
#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/camera/CameraModel.h"
#include "core/gl/Objects.h"
#include "core/math/Pose.h"
#include "render/CameraProjection.h"
#include "render/GpuScene.h"
#include "render/GpuTypes.h"
#include "render/Resource.h"
#include "render/passes/exposure/ExposureMatchOptions.h"

namespace mirage::render {

// How rough glass blurs what is seen through it (docs/specular.md, "Rough refraction").
enum class RoughRefractionMethod {
    Filter,  // the fuzzy pass's image-space filter with the transmitted lobe (render/passes/fuzzy)
    Lean,    // LEAN-mapped back-face normals, one Gaussian lobe per pixel (render/passes/rough)
    Gsr,     // the same with the back NDF reduced to one Gaussian per hemisphere subdivision
};
const char* roughRefractionMethodName(RoughRefractionMethod m);  // "filter", "lean", "gsr"

// The rectangles (GL window x, y, width, height) that draws into a set of textures last covered.
// Clearing those and the next draw's rectangles before that draw keeps the textures at their
// clear value outside the new rectangles, as a full clear would, at the cost of those pixels
// only (full-screen clears of the specular passes' float targets cost llvmpipe several ms a
// frame). A new texture's contents are undefined: markAll() after allocating one.
struct DrawnRects {
    DrawnRects() { markAll(); }
    void markAll() { rects.assign(1, glm::ivec4(0, 0, 1 << 24, 1 << 24)); }
    std::vector<glm::ivec4> rects;
};

struct RendererOptions {
    int vplCount = 256;          // total VPLs per frame, split over the lights with RSMs
    int shadowMapSize = 512;     // texels per side of each shadow / RSM layer
    int ismTileSize = 64;        // texels per side of one VPL's imperfect shadow map
    int ismPointsPerVpl = 1024;  // surface points splatted into each VPL's ISM
    int interleave = 4;          // K: each pixel gathers vplCount / K^2 VPLs
    // VPL gather at 1/scale resolution per axis, 1..4, upsampled by the geometry-aware filter; 0:
    // automatic, gatherScale(): a gather pixel every ~1/160 of the canvas width whatever the
    // resolution, so that the indirect light keeps its detail relative to the image.
    int indirectScale = 0;
    float vplDistanceClamp = 0.1f;  // metres: VPL distance below this is clamped (no spikes)
    float shadowBias = 0.001f;      // metres: constant depth bias of the shadow-map test
                                    // (lighting.glsl adds 1.5 texels' footprint / cos)
    // History weight of every temporally smoothed buffer (0 = off): the VPL lighting (gifilter),
    // and where switched on below the caustic buffer and the specular-hit light L'. Each frame
    // keeps (1 - temporalBlend) of its own value: an exponential average over ~1 / (1 - blend)
    // frames. 0 .. 0.98.
    float temporalBlend = 0.8f;
    // Rendered linear radiance -> camera linear units: the gain of every frame, or with
    // exposureMatch.enabled the prior of the per-frame estimate (docs/camera-matching.md).
    float exposure = 1.0f;
    ExposureMatchOptions exposureMatch;  // render/passes/exposure
    float alphaMax = 8.0f;               // cap of alpha = CI / L_r
    float alphaFadeLr = 0.02f;           // where L_r (linear) is below this, alpha fades to 1
    float nearM = 0.01f, farM = 100.0f;  // camera clip planes (metres)
    // Specular objects (docs/specular.md).
    int refractionMarchSteps = 16;        // back-face depth march steps of the refracted ray
    float backProjectionEpsilon = 0.02f;  // depth validation: |d - d_gbuf| < eps * d + 0.005 m
    bool specularVpls = true;             // light GBuf_refl / GBuf_refr hits with the VPLs too
    // A VPL whose reflective-shadow-map sample lands on a mirror or glass continues to the
    // reflected or refracted photon's receiver (Knecht 2013 Sec. 5.2), for spot lights with
    // photon G-buffers (caustics on); false: it stays on the mirror / glass, which scatters no
    // diffuse light (the VPL is dark).
    bool reflectedRefractedVpls = true;
    // Glass transmits light in the shadow maps (coloured, Fresnel and Beer-Lambert weighted);
    // false: glass is an opaque occluder, as mirrors are.
    bool glassShadows = true;
    // Caustics from spot lights (Knecht 2013 Sec. 4.2, 5.2; docs/caustics.md): photon G-buffers
    // of causticMapSize^2 texels per spot light whose cone holds a mirror or glass object (the
    // frustum fitted to the objects' bounding sphere), splatted as quads whose world radius is
    // causticQuadScale x the spacing of neighbouring photons on the receiver (Wyman 2008).
    bool caustics = true;
    int causticMapSize = 256;
    float causticQuadScale = 1.5f;
    // Caustics seen in reflections and refractions (docs/caustics.md): the photons sorted into a
    // world-space hashed grid (render/passes/caustic PhotonGridPass) and gathered at every
    // reflected / refracted hit by the specular light pass, with each photon's kernel radius
    // (causticQuadScale photon spacings, widened to 1.5 of the hit's pixel footprints) at most
    // causticGatherRadius metres, or up to twice that where the pixels are coarser (the grid's
    // cells are twice it: the gather's cost grows with it). false: those hits get no caustic.
    bool causticGather = true;
    float causticGatherRadius = 0.01f;
    // Photons the gather reads per grid bucket (0: all). A focused caustic puts tens of thousands
    // of photons into one cell, and every hit near it would read them all (a glass sphere alone
    // under a spot: the specular light pass 20x slower). Above the cap, a bucket is read with a
    // stride (every s-th photon from a per-pixel offset) and what is read is weighted
    // by count / read, so the estimate keeps its expectation and gains noise only where photons
    // are dense. Off by default: which photons a stride reads depends on the order the grid's
    // scatter put them in, which atomics on a multithreaded rasteriser (llvmpipe) vary from run to
    // run, so a capped frame is not reproducible (measured: up to 0.4 % of the peak between two
    // renderers of the same frame); replays and sharded runs are expected to be.
    int causticGatherCap = 0;
    // Temporal smoothing of the caustic buffer (Knecht 2013 end of Sec. 4.2; render/passes/caustic
    // caustic_resolve.frag): this frame's caustic irradiance blended with last frame's,
    // reprojected by the receiver's world position and rejected where the surface there is at
    // another distance, with the GI filter's reset rules (render/TemporalHistory.h). A tracked
    // camera jitters every frame, which moves the photon footprints over the pixels: without it
    // the caustic shimmers. false: every frame's caustic stands alone.
    bool causticTemporal = true;
    // The same for the light of the reflected / refracted hits, L'_rv and L'_r (gathered caustic
    // included; render/passes/specular specular_light.frag), reprojected by the mirror / glass
    // surface's position and rejected also where either ray's hit distance changed (a
    // reflection's hit moves differently from the mirror under camera motion).
    bool specularTemporal = true;
    // Fuzzy reflections of rough metals (render/passes/fuzzy, docs/specular.md): the image-space
    // filter (Kulikova and Dmitriev, Eqs. 1-5) over the mirror-ray buffers. fuzzyConeDeg is the
    // cone bound Theta (degrees) that limits each pixel's kernel (Eq. 4); fuzzyTaps the taps per
    // side of each separable pass (a wider kernel is sampled with a stride). false: the rough
    // metal's reflection stays sharp (its roughness ignored; for comparison).
    bool fuzzyReflections = true;
    float fuzzyConeDeg = 20.0f;
    int fuzzyTaps = 12;
    // Rough glass (render/passes/rough, docs/specular.md): which method blurs the refraction;
    // gsrSubdivisions = the hemisphere sectors of the Gaussian sum reduction (1..8);
    // roughMipLevels = levels of the LEAN moment chains and of the prefiltered lookups (camera
    // image, rough-glass radiance; 1..12): a lobe wider than the last level is cut there.
    RoughRefractionMethod roughRefraction = RoughRefractionMethod::Lean;
    int gsrSubdivisions = 4;
    int roughMipLevels = 8;
    // 1, 4 or 16: each hit sums every stride-th VPL (x stride), interleaved over 2x2 / 4x4
    // pixels; each hit's VPL irradiance is then averaged over its 2x2 quad (specular_light.frag),
    // so a quad sums 4 subsets. 16 costs about half of 4's speclight time; the quad average keeps
    // its pattern weak enough for the specular tests' SSIM floors (docs/specular.md, "Cost").
    int specularVplStride = 16;
    // Specular lighting (speclight) at half the canvas resolution per axis: each 2x2 block's
    // first specular pixel is shaded (lights, VPLs, caustic photons at its hits) and the canvas
    // pixels take the hit radiance from the four half pixels around them, weighted by how well
    // the representatives' hits match theirs (same object, tangent plane, normal), multiplied
    // back by their own hit albedo, Fresnel weight and emission; L_env stays per pixel
    // (specular_resolve.frag, docs/specular.md "Cost"). false: every specular pixel is shaded.
    bool specularHalfResolution = false;
    // Tests only: false drops the upsample's geometry test (plain bilinear weights; halos at
    // depth steps in the reflections).
    bool specularUpsampleGeometry = true;
    // Tests only: false draws the specular passes over the one rectangle around every specular
    // object (FrameContext::specularScissor) instead of each object's own (the same images).
    bool specularRectsPerObject = true;
    // false (the default): `direct` (with the GI upsample) and the composite's diffuse variant skip
    // the pixels that show a mirror or glass object (their light comes from the specular passes;
    // FrameContext::drawFullscreenTriangleOutsideSpecular). true: they shade them too (tests
    // compare the two).
    bool diffuseOnSpecularPixels = false;
    // Where the lens remap is the identity (no distortion, a canvas of the camera's size) the
    // composite reads each canvas buffer at its own pixel (CompositePass::isIdentityRemap).
    // false: it reads through the remap table there too (tests compare the two).
    bool compositeIdentityRemap = true;
    // true: in frames with VPL light the direct-light pass also writes the direct light alone
    // (DirectRv / DirectR; two more canvas targets), besides the GI solutions LRv / LR it sums
    // with the upsampled indirect light. false (the default): DirectRv / DirectR exist only in
    // frames without VPL light, where they are LRv / LR.
    bool keepDirectLight = false;
    // Reuse the camera-independent passes' output (shadow maps, RSMs, VPLs, ISMs) while the
    // frame plan is unchanged, instead of re-rendering it every frame (false: always re-run).
    bool reuseStaticPasses = true;
    bool cullPasses = true;  // run only the passes the scene needs (false: run all; tests)
    // glFinish around every pass, each timed by the wall clock between the two (PassReport::gpuMs).
    // llvmpipe defers rasterisation until a later sync (a compute dispatch that reads the result,
    // a readback), so without this a pass's time can show up in the next pass's timer query, and
    // its queries miss compute dispatches. For benchmarks.
    bool syncPasses = false;
    // false: the composite is the footage unchanged, as if no virtual object existed (the live
    // view's "hide" key; the bench's `virtual=off` sanity point, which must score as the footage).
    bool showVirtual = true;

    // Reflected-scene impostors for specular objects (render/passes/impostor).
    int impostorResolution = 256;  // texels per side of each impostor and cube face
    // Secant refinement steps of the height-field search. 2: the first step removes most of the
    // hit error (docs/impostors.md) and the composite is within 0.01 dB of 4 or 8 steps.
    int impostorRefineSteps = 2;
    bool impostorCubeMapBaseline = false;  // true: plain G-buffer cube map, looked up by direction

    // Live environment (render/passes/environment, docs/environment.md): width of the
    // equirectangular map built from each environment-camera frame (height = width / 2).
    int environmentMapWidth = 512;
    // The real light, placed (docs/environment.md, "Light estimation"): at most this many of the
    // dominant lights found in each live environment frame become shadow-casting REAL
    // directional lights, and the diffuse environment light is projected from the map without
    // them (render/EnvironmentLights.h). 0: none (the environment's SH9 holds all its light).
    // The scene's lights plus these are at most kMaxLights.
    int environmentLights = 0;
    // Width of the map the lights are found on (CPU, height = width / 2).
    int environmentLightMapWidth = 256;

    // Translucent objects (render/passes/translucency, docs/translucency.md): a voxel number
    // map per translucent object (up to 8), vnmResolution voxels along its longest side (the tau
    // LUT grows with the square of the surface voxels, ~36 n^4 bytes for a cube), its LUT cached
    // in vnmCacheDir (empty: precomputed every time a renderer is created). false: translucent
    // objects are drawn as opaque surfaces of their base colour.
    bool translucency = true;
    // A translucent object lets light through in the shadow maps (Fresnel at each crossing, its
    // optical thickness along the light's ray; docs/translucency.md "Shadows"); false: it is an
    // opaque occluder.
    bool translucentShadows = true;
    int vnmResolution = 16;
    std::string vnmCacheDir;

    // Throws mirage::Error naming the first option out of range and its valid range. The
    // Renderer calls it once, before anything is allocated.
    void validate() const;
    // The gather scale for a canvas this wide: indirectScale, or when 0 width / 160 in 1..4
    // (4 at 640x480, 2 at 320x240, 1 at 160x120).
    int gatherScale(int canvasWidth) const {
        return indirectScale > 0 ? indirectScale : std::clamp(canvasWidth / 160, 1, 4);
    }
};

// Tiles per row of the imperfect shadow map atlas (one square tile per VPL).
int ismTilesPerRow(int vplCount);

// The environment camera feeding the environment light, as the environment pass sees it
// (Renderer::setEnvironmentCamera / updateEnvironment / useStaticEnvironment).
struct EnvironmentInput {
    bool live = false;        // a camera frame is the environment (false: the scene's map)
    uint64_t generation = 0;  // changes with every new frame and every live <-> static switch
    double time = 0.0;        // seconds: the frame's time on the environment camera's clock
    CameraIntrinsics camera;  // the environment camera (fish-eye: Kannala-Brandt)
    double reachDeg = -1.0;   // the calibration's reach off-axis (<= 0: whole projectable field)
    Pose T_world_camera;      // the camera's pose (OpenCV axes) when the frame was taken
    glm::vec3 gain{1.0f};     // linearised pixel value -> scene radiance, per channel (R, G, B)
    // Lights placed from this frame (RendererOptions::environmentLights): the diffuse light is
    // then the SH9 of the map without them, computed on the CPU (render/EnvironmentLights.h),
    // instead of the projection of the map on the GPU.
    bool lightFreeSHValid = false;
    std::array<glm::vec3, 9> lightFreeSH{};
    float lightFreeSeenFraction = 1.0f;  // solid-angle fraction of the map the camera saw
};

struct LightPlan {
    bool castsShadow = false;       // some caster inside the light's cone
    bool needsRealOnlyMap = false;  // a virtual caster in the cone of a REAL light
    bool reachesVirtual = false;    // a virtual object inside the light's cone
    bool hasRsm = false;            // VPLs are placed from this light
    // Glass in the cone transmits this light in the shadow maps (ShadowGlass atlases); a light
    // with a real-only shadow map also gets a real-only glass layer (real glass only).
    bool glassTransmits = false;
    // A translucent object in the cone transmits this light in the same atlases (its medium's
    // optical thickness), whether or not the light has caustics.
    bool translucentTransmits = false;
    bool needsRealOnlyGlass = false;
    // The light has glass atlases: glass or a translucent object transmits it.
    bool hasGlassLayer() const { return glassTransmits || translucentTransmits; }
    // Caustics: a spot light with a specular object in its cone gets photon G-buffers (layer
    // causticLayer) rendered through causticViewProj (world -> clip, fitted to the specular
    // objects' bounding sphere; tan of its half angle causticTanHalf). Glass is then opaque in
    // this light's shadow maps: the photons carry the light through it (as in the reference).
    bool caustics = false;
    int causticLayer = -1;
    glm::mat4 causticViewProj{1.0f};
    float causticTanHalf = 1.0f;
    int firstLayer = 0, layers = 0;  // in the shadow / RSM atlases
    int firstVpl = 0, vplCount = 0;
    std::string reason;
};

struct FramePlan {
    std::vector<LightPlan> lights;
    int shadowLayers = 0;
    bool needVpls = false;
    bool needRealOnlyShadows = false;
    bool glassShadows = false;  // some light's shadow maps have glass (ShadowGlass written)
    bool needRealOnlyGlass = false;
    int causticLayers = 0;           // spot lights with photon G-buffers this frame
    float causticIrradiance = 0.0f;  // W/m^2: the largest I / d^2 of a caustic light at its objects
    std::string causticReason;
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
    // The frame's part of the temporal history rule (render/TemporalHistory.h): false in the
    // first frame, after a cut / seek / tracking loss (FrameInput::resetHistory) and after
    // objects moved (Renderer::updateTransforms); historyResetReason says which.
    bool historyValid = false;
    std::string historyResetReason;
    EnvironmentInput environment;
    // The gain from rendered radiance to camera units in force this frame (frame.exposure), with
    // where it came from: the exposure pass's estimate, or RendererOptions::exposure.
    ExposureState exposure;
    // The camera's own exposure report (time x gain, any unit; Renderer::setReportedExposure).
    std::optional<double> reportedExposure;
    // What the camera-independent passes' output depends on besides the static scene: the light
    // matrices and parameters and the frame plan (Renderer sets it before every frame; equal keys
    // mean equal shadow maps).
    std::string staticKey;
    // Canvas pixels (GL window rect: x, y, width, height) that can show a mirror or glass object
    // this frame (width 0: none in view). The specular passes shade only these: on llvmpipe a
    // fragment costs its whole shader even where it exits at once.
    glm::ivec4 specularScissor{0, 0, 0, 0};
    // The same per specular object, rectangles that overlap merged into their bounding one:
    // together they hold every specular pixel, and where a mirror and a glass object lie apart
    // on screen far fewer pixels than specularScissor (the draws over them pay per pixel
    // covered, masked or not). refractiveRects: the glass objects' only, all the refraction
    // search needs (a mirror's pixel refracts nothing). Both empty when none is in view.
    std::vector<glm::ivec4> specularRects, refractiveRects;

    gl::Buffer frameUbo, lightUbo;
    gl::VertexArray emptyVao;  // for full-screen triangles

    const gl::Texture& blackTexture() const { return black_; }          // 1x1 RGBA16F zero
    const gl::Texture& farShadowTexture() const { return farShadow_; }  // 1x1 array, 1e30
    // 1x1 RGBA32F array (0, 0, 0, 1e30): no glass between any light and any point.
    const gl::Texture& noGlassTexture() const { return noGlass_; }

    int canvasWidth() const { return projection.canvasWidth; }
    int gatherScale() const { return options.gatherScale(canvasWidth()); }
    int canvasHeight() const { return projection.canvasHeight; }
    void bindFrameBlocks() const;
    // Full-screen pass set-up: viewport width x height, depth test and blending off, `program`
    // in use and the frame's uniform blocks bound (the pass binds its framebuffer first).
    void beginFullscreen(const gl::Program& program, int width, int height) const;
    // The full-screen triangle of fullscreen.vert (no vertex data: emptyVao).
    void drawFullscreenTriangle() const;
    // Clears colour attachments first .. first + count - 1 of the bound framebuffer to 0 and,
    // with clearDepth, its depth attachment to 1 (depth writes must be on) inside drawn.rects
    // and `rects`; then drawn.rects = rects (see DrawnRects).
    void clearForRects(const std::vector<glm::ivec4>& rects, DrawnRects& drawn, int first,
                       int count, bool clearDepth = false) const;
    // The full-screen triangle in each of `rects` (which must not overlap: see
    // mergeOverlappingRects); clears nothing.
    void drawFullscreenTriangleIn(const std::vector<glm::ivec4>& rects) const;
    // The full-screen triangle on every canvas pixel that does not show a mirror or glass object
    // (the composite takes those pixels' light from the specular passes): the bound framebuffer
    // has the frame's SpecularMask as its depth attachment (0 on specular pixels, 1 elsewhere),
    // and the triangle at depth 0.5 passes GL_LESS only where it is 1, so llvmpipe's early depth
    // test skips the blocks of specular pixels before the shader runs. Colour attachments
    // first .. first + count - 1 are cleared to 0 inside specularRects first (what is not drawn).
    void drawFullscreenTriangleOutsideSpecular(int first, int count) const;

private:
    gl::Texture black_, farShadow_, noGlass_;
};

// `rects` (GL window x, y, width, height) with every overlapping pair replaced by its bounding
// rectangle until none overlaps, empty ones dropped: the same pixels covered or more, each once.
std::vector<glm::ivec4> mergeOverlappingRects(std::vector<glm::ivec4> rects);

}  // namespace mirage::render
