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
#include "render/PassOptionSet.h"
#include "render/Resource.h"
#include "render/passes/aa/AntialiasOptions.h"
#include "render/passes/caustic/CausticOptions.h"
#include "render/passes/composite/CompositeOptions.h"
#include "render/passes/direct/DirectOptions.h"
#include "render/passes/environment/EnvironmentOptions.h"
#include "render/passes/exposure/ExposureMatchOptions.h"
#include "render/passes/fuzzy/FuzzyOptions.h"
#include "render/passes/grain/GrainOptions.h"
#include "render/passes/impostor/ImpostorOptions.h"
#include "render/passes/indirect/IndirectOptions.h"
#include "render/passes/ism/IsmOptions.h"
#include "render/passes/motionblur/MotionBlurOptions.h"
#include "render/passes/rough/RoughOptions.h"
#include "render/passes/shadow/ShadowOptions.h"
#include "render/passes/specular/SpecularOptions.h"
#include "render/passes/translucency/TranslucencyOptions.h"
#include "render/passes/vpl/VplOptions.h"

namespace mirage::render {

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

// How the frame graph runs the passes (for every scene; tests and benchmarks change them).
struct FrameGraphOptions {
    // Reuse the camera-independent passes' output (shadow maps, RSMs, VPLs, ISMs) while the
    // frame plan is unchanged, instead of re-rendering it every frame (false: always re-run).
    bool reuseStaticPasses = true;
    bool cullPasses = true;  // run only the passes the scene needs (false: run all; tests)
    // glFinish around every pass, each timed by the wall clock between the two (PassReport::gpuMs).
    // llvmpipe defers rasterisation until a later sync (a compute dispatch that reads the result,
    // a readback), so without this a pass's time can show up in the next pass's timer query, and
    // its queries miss compute dispatches. For benchmarks.
    bool syncPasses = false;
};

// Every pass's options, one member per pass folder that has any (each struct, its defaults and its
// validation live in that folder), plus the few that steer the whole frame.
struct RendererOptions {
    VplOptions vpl;
    IndirectOptions indirect;
    IsmOptions ism;
    ShadowOptions shadow;
    DirectOptions direct;
    CausticOptions caustic;
    SpecularOptions specular;
    FuzzyOptions fuzzy;
    RoughOptions rough;
    ImpostorOptions impostor;
    EnvironmentOptions environment;
    TranslucencyOptions translucency;
    CompositeOptions composite;
    ExposureMatchOptions exposureMatch;  // render/passes/exposure
    MotionBlurOptions motionBlur;        // render/passes/motionblur
    AntialiasOptions aa;                 // render/passes/aa
    GrainOptions grain;                  // render/passes/grain: noise and vignetting

    // History weight of every temporally smoothed buffer (0 = off): the VPL lighting (gifilter),
    // and where switched on the caustic buffer and the specular-hit light L'. Each frame keeps
    // (1 - temporalBlend) of its own value: an exponential average over ~1 / (1 - blend) frames.
    // 0 .. 0.98.
    float temporalBlend = 0.8f;
    FrameGraphOptions graph;  // how the frame graph runs the passes
    // The options of every pass registered after the members above, each struct in its pass's
    // folder (render/PassOptionSet.h): adding a pass adds no member here.
    PassOptionSet passes;

    // Throws mirage::Error naming the first option out of range and its valid range. The
    // Renderer calls it once, before anything is allocated.
    void validate() const;
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
    // Lights placed from this frame (RendererOptions::environment.lights): the diffuse light is
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
    // The virtual occluders get maps of their own, each fitted to a group of them
    // (GpuLight::focusViewProj): a real light with real and virtual occluders in its cone whose
    // virtual ones fill small parts of it. The shadow-map texels are then much finer where the
    // virtual objects' shadows fall, which is what the differential (L_rv - L_r) shows:
    // visibility through all occluders is the real map's times the virtual ones' (lighting.glsl).
    // focusDraws[k]: the scene draws in focused map k (ShadowMaps layer firstFocusLayer + k,
    // after every light's own layers).
    std::vector<std::vector<int>> focusDraws;
    // With focused maps: the virtual occluders in none of them (glass opaque to this light
    // because its caustics carry the light through, or glass shadows are off: where photons
    // carry it, its shadow's edge is where they take over, not a hard edge), drawn into the
    // light's own layers of ShadowMaps.
    std::vector<int> unfocusedDraws;
    int firstFocusLayer = 0;
    bool focusedVirtual() const { return !focusDraws.empty(); }
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
    int focusLayers = 0;  // focused virtual-occluder maps, after shadowLayers in ShadowMaps
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
    // The frame's time (seconds on the footage's clock; FrameInput::time), NaN when unknown.
    double time = 0.0;
    // The camera of the frame rendered before this one (the motion blur's velocity); none in the
    // renderer's first frame.
    struct PreviousCamera {
        glm::mat4 viewProj{1.0f};  // world -> GL clip
        double time = 0.0;         // seconds (NaN: unknown)
    };
    std::optional<PreviousCamera> previous;
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
    // where it came from: the exposure pass's estimate, or RendererOptions::composite.exposure.
    ExposureState exposure;
    // The camera's own exposure report (time x gain, any unit; Renderer::setReportedExposure).
    std::optional<double> reportedExposure;
    // The footage's noise and vignetting as estimated over the frames so far (the grain pass),
    // and the vignetting in force (RendererOptions::grain.vignette.profile, else the estimate;
    // none before the first): the exposure pass divides its blocks by it, so that the gain is
    // the one at the principal point.
    GrainEstimates grainEstimates;
    std::optional<VignetteProfile> vignette;
    std::string vignetteNote = "none yet (no profile given, nothing estimated)";
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
    // specularRects split by whether a glass object's rectangle meets them: the mirror rectangles
    // hold mirrors and metals only (no pixel of them refracts), so the specular passes shade
    // them with their reflection-only variants (llvmpipe pays for every branch's code).
    std::vector<glm::ivec4> glassSpecularRects, mirrorRects;
    // Canvas pixels that can show a translucent object, per object, overlapping ones merged
    // (empty when none is in view): the composite's translucent variant runs on these only.
    std::vector<glm::ivec4> translucentRects;

    gl::Buffer frameUbo, lightUbo;
    gl::VertexArray emptyVao;  // for full-screen triangles

    const gl::Texture& blackTexture() const { return black_; }          // 1x1 RGBA16F zero
    const gl::Texture& farShadowTexture() const { return farShadow_; }  // 1x1 array, 1e30
    // 1x1 RGBA32F array (0, 0, 0, 1e30): no glass between any light and any point.
    const gl::Texture& noGlassTexture() const { return noGlass_; }

    int canvasWidth() const { return projection.canvasWidth; }
    int gatherScale() const { return options.indirect.gatherScale(canvasWidth()); }
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
// GL window rectangles (x, y, width, height) a and b share a pixel.
bool rectsOverlap(const glm::ivec4& a, const glm::ivec4& b);
// Merges each list and moves every mirror rectangle that meets a glass one into the glass list
// (merged again), so that no pixel is drawn by both lists' variants.
void separateMirrorRects(std::vector<glm::ivec4>& glass, std::vector<glm::ivec4>& mirror);

}  // namespace mirage::render
