#pragma once
// The real-time renderer: differential instant radiosity (Knecht et al. 2010, 2013 Sec. 3.1)
// compositing a scene's virtual objects into camera footage. The frame is a graph of passes
// (render/FrameGraph.h; one folder per pass in render/passes/), built once here: the renderer
// plans each frame from the scene (which lights cast shadows, which need real-only visibility,
// whether VPLs are needed, whether a specular object is in view), the graph runs only the passes
// the frame needs, times each (PassReport::gpuMs) and reports which ran and why
// (`mirage info --passes SCENE` prints it, docs/realtime-renderer.md draws it). Needs a current
// GL 4.5 context (core/gl/Context.h).
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/camera/CameraResponse.h"
#include "core/gl/Objects.h"
#include "core/math/Pose.h"
#include "core/scene/Scene.h"
#include "render/CameraProjection.h"
#include "render/EnvironmentCamera.h"
#include "render/EnvironmentLights.h"
#include "render/FrameContext.h"
#include "render/FrameGraph.h"
#include "render/GpuScene.h"
#include "render/RenderPass.h"

namespace mirage::render {

struct FrameInput {
    Pose T_world_camera;        // camera pose (OpenCV camera axes), world = glTF frame
    cv::Mat cameraImage;        // 8-bit BGR, sRGB-encoded, camera size; empty = black footage
    bool resetHistory = false;  // a cut, a seek or tracking loss: drop temporal history
    // Seconds on the footage's clock (frames.csv's t_main; live: the capture time). The motion
    // blur scales the motion since the last rendered frame by shutter / (time - its time); NaN
    // (unknown) leaves the frame unblurred.
    double time = std::numeric_limits<double>::quiet_NaN();
};

class Renderer {
public:
    Renderer(const Scene& scene, const CameraIntrinsics& camera, RendererOptions options = {});
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    // Renders and composites one frame; blocks until its timer queries are available.
    const FrameReport& render(const FrameInput& input);

    // Moves objects and lights to `scene`'s node transforms: `scene` is the scene this renderer
    // was built from with other node matrices (a placement being dragged, an animation). The
    // next render() redoes in that frame what depends on where things stand (shadow maps, VPLs,
    // ISMs, the specular objects' impostors, caustics; the report says why each ran) and drops
    // the temporal history. Returns false, changing nothing, when a translucent object would
    // move (its voxel number map is precomputed in the world: build a new Renderer). Throws
    // mirage::Error, changing nothing, when `scene` has other meshes or lights.
    bool updateTransforms(const Scene& scene);

    // The environment camera as a live light source (docs/environment.md). After
    // setEnvironmentCamera, each updateEnvironment frame replaces the scene's static environment
    // (map, diffuse SH9 and L_env) from the next render() on; the environment pass runs only in
    // the frames after a new one arrived. A camera mounted on the main camera takes its pose
    // from the next render()'s T_world_camera. Throws mirage::Error on invalid intrinsics.
    void setEnvironmentCamera(const EnvironmentCameraSetup& camera);
    // A new environment-camera frame: 8-bit BGR, sRGB-encoded, the calibration's size; `time` in
    // seconds on its clock. Returns false and changes nothing when `time` is the last frame's (the
    // same frame again). Throws mirage::Error (nothing changed) when no camera is set or the
    // image's size or type differs from the calibration's.
    bool updateEnvironment(const cv::Mat& frameBgr8, double time);
    // Per-channel gain of the environment camera (EnvironmentCameraSetup::gain); rebuilds the
    // live map at the next render().
    void setEnvironmentGain(const glm::vec3& gain);
    // Back to the scene's static environment (the environment stream ended or failed).
    void useStaticEnvironment();
    bool environmentLive() const { return ctx_->environment.live; }
    // The lights found in the live environment and placed as shadow-casting REAL directional
    // lights (RendererOptions::environment.lights > 0), with the maps they were found on: updated
    // in the render() after each new environment frame; empty without a live environment.
    const EnvironmentLightSplit& environmentLights() const { return envLights_; }
    // This frame's environment map, level 0, as CV_32FC4 (R, G, B linear radiance; A = 1 where
    // the camera saw the direction, 0 where it was filled in; 1 everywhere for a static map),
    // top row first, and its SH9 block. For tests, benchmarks and light estimation.
    cv::Mat readEnvironmentMap() const;
    GpuEnvironment readEnvironmentLight() const;

    // Readbacks (camera image size, top row first). Linear RGB float (CV_32FC3) / sRGB 8-bit
    // BGR (CV_8UC3) / coverage (CV_8U: 0 empty, 1 real, 2 virtual).
    cv::Mat compositeLinear() const;
    cv::Mat compositeSrgb() const;
    // The composite in the main camera's own codes (its response, setCameraResponse): what a
    // recording or a window shows beside the camera's footage. compositeSrgb() for an sRGB camera.
    cv::Mat compositeCameraCoded() const;

    // The main camera's response (RendererOptions::composite.cameraResponse).
    const CameraResponse& cameraResponse() const { return options_.composite.cameraResponse; }
    cv::Mat coverage() const;
    // Any canvas-size linear buffer of this frame (LRv, LR, DirectRv, ...) as CV_32FC3 RGB,
    // top row first; a depth buffer (SpecularMask) as CV_32FC1. Throws mirage::Error if the frame
    // did not produce it.
    cv::Mat readBuffer(Resource r) const;
    // The imperfect shadow map atlas of this frame (all points, or real points only) as CV_32F
    // distances in metres, +inf where no point was splatted. Throws if no ISM ran.
    cv::Mat readIsmAtlas(bool realOnly) const;
    // This frame's VPLs (RendererOptions::vpl.count slots; unused ones have valid = 0). Throws if
    // no VPL pass ran.
    std::vector<GpuVpl> readVpls() const;

    // The composite as an sRGB8 texture (camera size, memory row 0 = image top row), e.g. to
    // blit into a window (flip vertically: GL windows put row 0 at the bottom). Valid after the
    // first render(); throws mirage::Error before.
    const gl::Texture& compositeTexture() const;

    const CameraProjection& projection() const { return projection_; }
    const FramePlan& plan() const { return ctx_->plan; }
    // The gain from rendered radiance to camera units this frame, per channel, and where it came
    // from (the per-frame estimate with RendererOptions::exposureMatch, else the fixed exposure).
    const ExposureState& exposure() const { return ctx_->exposure; }
    // The camera's own report of its exposure (exposure time x gain, any unit: only its changes
    // count) for the next render() calls, where the camera or the session gives one (nullopt:
    // none): the prior of the per-frame estimate for changes (render/ExposureTracker.h).
    void setReportedExposure(std::optional<double> exposure) { ctx_->reportedExposure = exposure; }
    // The footage's noise and vignetting estimated so far (RendererOptions::grain), each with a
    // note saying what was used; and the vignetting applied to the virtual pixels (none before
    // one is given or estimated: vignettingNote says so).
    const GrainEstimates& grainEstimates() const { return ctx_->grainEstimates; }
    const std::optional<VignetteProfile>& vignetting() const { return ctx_->vignette; }
    const std::string& vignettingNote() const { return ctx_->vignetteNote; }
    // This frame's canvas rectangles of the specular / glass objects (FrameContext).
    const std::vector<glm::ivec4>& specularRects() const { return ctx_->specularRects; }
    const std::vector<glm::ivec4>& refractiveRects() const { return ctx_->refractiveRects; }
    const GpuScene& gpuScene() const { return *scene_; }
    const RendererOptions& options() const { return options_; }
    // Takes the options a frame-time governor may change between frames (render/governor/
    // GovernedKnobs.h: specular resolution, VPL stride at the hits, refraction and impostor
    // steps, caustic gather cap and refresh interval) from `quality`, from the next
    // render() on; every other option stays as built. Throws mirage::Error (nothing changed) when
    // they are out of range.
    void setQuality(const RendererOptions& quality);
    const FrameReport& lastReport() const { return graph_.lastReport(); }
    // The passes in frame order (the columns of every per-pass table: replay CSV, bench).
    std::vector<std::string> passNames() const;
    // The frame graph: declarations, and what the last frame did (FrameGraph::describe / dot).
    const FrameGraph& graph() const { return graph_; }

private:
    void planFrame(const FrameInput& input);
    void writeFrameUniforms(const FrameInput& input, const glm::mat4& view, const glm::mat4& proj);
    void placeEnvironmentLights();
    void uploadCameraImage(const cv::Mat& bgr);

    RendererOptions options_;
    std::unique_ptr<GpuScene> scene_;
    CameraProjection projection_;
    std::unique_ptr<FrameContext> ctx_;
    FrameGraph graph_;
    gl::Texture cameraImage_;
    std::optional<EnvironmentCameraSetup> envCamera_;
    gl::Texture envImage_;         // the environment camera's newest frame, sRGB8
    bool envPosePending_ = false;  // a mounted camera's pose is taken at the next render()
    cv::Mat envFrame_;             // the newest environment frame (BGR8), to find lights in
    EnvironmentLightFinder envLightFinder_;
    EnvironmentLightSplit envLights_;
    uint64_t envLightsGeneration_ = UINT64_MAX;  // the environment generation they were found in
    glm::mat4 prevViewProj_{1.0f};
    glm::vec3 prevCameraPos_{0.0f};
    double prevTime_ = 0.0;      // the last rendered frame's FrameInput::time
    bool objectsMoved_ = false;  // updateTransforms moved something since the last render()
};

}  // namespace mirage::render
