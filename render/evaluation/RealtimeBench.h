#pragma once
// Speed against error (`mirage bench`, docs/bench.md): the real-time renderer run over the frames
// of a synthetic session at the ground-truth poses, for a grid of knobs, each configuration judged
// against the reference renderer's ground-truth composite (GroundTruthComposite.h) by PSNR/SSIM
// over the whole frame and over the pixels the virtual objects influence, and timed per pass with
// RendererOptions::graph.syncPasses (each pass alone between two glFinish, timed by the wall
// clock).
//
// Knobs are a list (benchKnobs()), not loops: a new knob (impostor resolution, refinement steps,
// caustic map size, ...) is one entry there, and the grid, CSV and table pick it up.
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/camera/CameraResponse.h"
#include "core/math/Pose.h"
#include "core/scene/Scene.h"
#include "core/session/Session.h"
#include "render/EnvironmentCamera.h"
#include "render/FrameContext.h"
#include "render/evaluation/ImageComparison.h"
#include "render/raytrace/GroundTruthComposite.h"

namespace mirage::render {

// One point of the grid: renderer options plus the render resolution.
struct BenchConfig {
    RendererOptions options;
    int width = 0, height = 0;                               // 0 = the session's size
    std::vector<std::pair<std::string, std::string>> knobs;  // (name, value) as applied
    // Light with the session's environment camera, updated every frame (knob env_source=camera;
    // docs/environment.md), instead of the scene's static environment map.
    bool environmentCamera = false;
    // Objects moving (knob moving_objects=on): before each frame the virtual objects are moved
    // 1 cm along the table and back in place (Renderer::updateTransforms), so every frame pays
    // for a move (shadow maps, VPLs, ISMs, caustics and impostors redone, history dropped) while
    // its image stays comparable with the session's ground truth.
    bool movingObjects = false;
    // Tracking-like noise on every frame's ground-truth pose (knob pose_jitter=MM): MM mm of
    // translation and MM / 10 degrees of rotation, 1 sigma (PoseJitter.h), a new draw per frame
    // and repeat. The ground truth stays at the exact pose, so the noise costs error in itself;
    // what it shows is what shimmers (temporal smoothing on / off).
    double poseJitterMm = 0.0;
    // Motion blur of what the renderer adds (knob motion_blur=on): the shutter is the session's
    // (BenchFrame::shutter); a session that states none is refused.
    bool motionBlur = false;
    // Supersampling of the renderer's layer (knob aa=ssaa2): the renderer runs at this many
    // times the width and height, over the footage enlarged by pixel replication (each footage
    // pixel stays one value in linear light), and its linear composite is box-averaged back to
    // the judging size, then sRGB-encoded. 1: none. A measured alternative to the aa pass
    // (docs/camera-matching.md, "Anti-aliasing"), not a renderer mode.
    int supersample = 1;
    // Linearise the footage with the session's camera response (knob camera_response=session),
    // or take it as sRGB whatever the calibration says (camera_response=srgb: the assumption a
    // camera without a measured response gets).
    bool sessionResponse = true;
    std::string label() const;  // "vpls=256 indirect_scale=2 ..."
};

struct BenchKnob {
    std::string name, help;
    // Default values of the full and --quick grids for a session camera.
    std::function<std::vector<std::string>(const CameraIntrinsics& session, bool quick)> defaults;
    // Sets the value on a configuration; throws mirage::Error naming the knob on a bad value.
    std::function<void(BenchConfig&, const std::string& value)> apply;
    // The knob's value in a configuration (what `apply` would have set).
    std::function<std::string(const BenchConfig&)> value;
};

// The knobs, in grid order (the first varies slowest).
const std::vector<BenchKnob>& benchKnobs();

// The configuration every grid starts from: RendererOptions' defaults at the session's size,
// with syncPasses on (per-pass GPU time); and each knob's value in it ("the default" of the
// results page: one point per knob setting varies one knob from here).
BenchConfig benchDefaultConfig();
std::map<std::string, std::string> benchDefaultKnobs();

// The grid: the cartesian product of every knob's values (defaults, or `overrides[name]`).
// Throws mirage::Error for an unknown knob name or a bad value.
std::vector<BenchConfig> benchGrid(
    const CameraIntrinsics& sessionCamera, bool quick,
    const std::map<std::string, std::vector<std::string>>& overrides);

// A frame of the session with everything the bench needs, at the session's size.
struct BenchFrame {
    int index = 0;        // frames.csv frame number
    Pose T_world_camera;  // ground truth (OpenCV camera axes)
    cv::Mat footage;      // 8-bit BGR sRGB, as the session stores it
    cv::Mat truth;        // ground-truth composite, 8-bit BGR sRGB
    cv::Mat influence;    // CV_8U, nonzero = influenced by the virtual objects
    cv::Mat edges;        // CV_8U: edgePixels(footage, truth, influence) at the judging size
    cv::Mat environment;  // the environment camera's frame of this row (8-bit BGR sRGB), if any
    double environmentTime = 0.0;  // its time (seconds, the environment camera's clock)
    double time = 0.0;             // the main camera's time of the frame (seconds, frames.csv)
    // The main camera's exposure time (seconds; session.json cameras[].shutter), if the session
    // states it: the motion blur's shutter (knob motion_blur=on).
    std::optional<double> shutter;
    // The main camera's response (its calibration's `response`; sRGB when it states none):
    // footage and truth stay in the camera's codes and the composite is judged in them.
    CameraResponse response;
};

// The main camera's frames of `session` that have a ground-truth pose and a ground-truth
// composite, from `start` (position in frames.csv), at most `maxFrames` (-1 = all). `skipped`
// counts frames without either. Throws FileError if a ground-truth image's size differs from the
// footage or the calibration.
std::vector<BenchFrame> loadBenchFrames(const Session& session, const GroundTruthInfo& truth,
                                        const CameraIntrinsics& mainCamera, int start = 0,
                                        int maxFrames = -1, int* skipped = nullptr);

struct BenchFrameResult {
    int index = 0;
    std::map<std::string, double> passMs;  // GPU ms per pass (0 or absent when skipped)
    double gpuMs = 0.0;                    // sum of the passes' GPU time
    double wallMs = 0.0;                   // CPU wall time of render() + composite readback
    CompositeError error;
};

struct BenchResult {
    BenchConfig config;
    bool baseline = false;               // the footage itself as "composite" (no virtual objects)
    std::vector<std::string> passOrder;  // every pass of the frame graph, in frame order
    std::vector<std::string> passes;     // those that ran at least once, in frame order
    std::map<std::string, double> medianPassMs;
    double medianGpuMs = 0.0, medianWallMs = 0.0;
    CompositeError error;  // pooled over all frames
    std::vector<BenchFrameResult> frames;
    cv::Mat firstComposite;  // the first frame's composite (8-bit BGR sRGB), for a look
    cv::Mat firstTruth;      // and its ground truth at the same size
};

// Scales a frame set to width x height (same aspect ratio as the session): footage and truth are
// averaged in linear light (the reference's box-filtered pixels stay box-filtered), a pixel is
// influenced if any pixel it covers was. Returns the input when the size already matches.
std::vector<BenchFrame> scaleFrames(const std::vector<BenchFrame>& frames, int width, int height);
// Intrinsics of the same camera at another resolution (pixel centres kept: OpenCV convention).
CameraIntrinsics scaleIntrinsics(const CameraIntrinsics& k, int width, int height);

// Runs one configuration over the frames (in order; temporal history reset on the first), each
// pass `repeats` times over the sequence (timings pooled, error from the last). Needs a current
// GL 4.5 context. `scene` is the scene with its virtual objects.
// `environment`: the session's environment camera, needed by configurations with
// environmentCamera (throws mirage::Error naming the knob without it or without frames).
BenchResult runBenchConfig(const Scene& scene, const CameraIntrinsics& sessionCamera,
                           const std::vector<BenchFrame>& frames, const BenchConfig& config,
                           int repeats = 1, const EnvironmentCameraSetup* environment = nullptr);

// The footage judged as if it were the composite: what a render with the virtual contribution
// removed scores. Every real configuration must beat it in the influenced pixels.
BenchResult footageBaseline(const std::vector<BenchFrame>& frames, int width = 0, int height = 0);

// A result as JSON and back, for the shards of a split bench (core/Shards.h). Everything the
// tables show survives exactly (non-finite numbers as "inf", "-inf", "nan"); of the configuration
// only its knobs and size come back (the renderer options are not stored), and no images.
nlohmann::json benchResultToJson(const BenchResult& result);
BenchResult benchResultFromJson(const nlohmann::json& json);

// Files: one row per configuration / per configuration and frame; a markdown table.
void writeBenchCsv(const std::string& path, const std::vector<BenchResult>& results);
void writeBenchFramesCsv(const std::string& path, const std::vector<BenchResult>& results);
// `preamble`: markdown put above the table (command, machine load, session).
void writeBenchMarkdown(const std::string& path, const std::vector<BenchResult>& results,
                        const std::string& preamble);

}  // namespace mirage::render
