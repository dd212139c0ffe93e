// `mirage live`: a live AR session (docs/live.md). A camera (V4L2, or a recorded video or
// session standing in for one, paced at its frame rate) is captured on its own thread with a
// latest-frame hand-off; the GL thread takes the newest frame, tracks the camera on the tag
// board, renders and composites the scene's virtual objects (the per-frame code replay uses,
// app/FrameCompositor.h) and shows the result in a window, or with --headless writes it.
//
// Outputs (all optional): -o OUT.mkv or a folder of PNG frames, with a per-frame CSV beside it
// (OUT.csv or OUT/frames.csv):
//   frame,t,state,reason,camera_frame,dropped,driver_dropped,tracking_ms,<pass>_ms...,gpu_ms,
//   readback_ms,
//   frame_ms,latency_ms,tx,ty,tz,qw,qx,qy,qz
// frame = processed frame number (from 0), t = capture time (seconds, CLOCK_MONOTONIC),
// camera_frame = the camera's frame counter, dropped = camera frames dropped before this one was
// taken (newer ones replaced them while processing was busy), driver_dropped = those the V4L2
// driver dropped (sequence-number gaps), latency_ms = output written (or
// shown) minus capture time. The pose is T_world_camera, numbers in their shortest exact form (the
// file is a poses file for `mirage replay --poses`).
// --record SESSION: the processed frames with their live poses (core/capture/LiveRecording.h).
#include <unistd.h>
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <functional>
#include <limits>
#include <optional>
#include <thread>

#include <epoxy/gl.h>

#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <opencv2/imgproc.hpp>

#include "app/BoardPlane.h"
#include "app/Command.h"
#include "app/EffectSwitches.h"
#include "app/FrameCompositor.h"
#include "app/InputChecks.h"
#include "app/NumberChecks.h"
#include "app/OutputKind.h"
#include "app/WindowSupport.h"
#include "core/Csv.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/camera/CalibrationFile.h"
#include "core/camera/Radiometry.h"
#include "core/capture/CameraCatalog.h"
#include "core/capture/CameraControls.h"
#include "core/capture/CaptureFormat.h"
#include "core/capture/LatestFrameCapture.h"
#include "core/capture/LiveRecording.h"
#include "core/capture/V4l2Camera.h"
#include "core/capture/V4l2Device.h"
#include "core/gl/Context.h"
#include "core/image/ImageIO.h"
#include "core/scene/Scene.h"
#include "core/scene/ScenePlacement.h"
#include "core/session/MatroskaWriter.h"
#include "core/session/Session.h"
#include "render/LightEstimation.h"
#include "render/Renderer.h"
#include "tracking/Tracker.h"

namespace mirage::app {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

struct LiveArgs {
    std::string camera, scene, calibration, board, output, record;
    std::vector<std::string> effectsOff;  // bench knob names of effects switched off
    double cameraFps = 0;                 // 0: the stand-in's own rate
    int width = 640, height = 480;
    int maxFrames = -1;
    int vpls = 256;
    float exposure = 1.0f;
    int jpegQuality = 92;
    bool headless = false;
    bool boardOnly = false;  // no natural features (extended tracking off)
    bool force = false;
    bool loop = false;  // a stand-in starts again at its end
    bool listCameras = false;
    std::string placement;          // default: <scene>.placement.json
    ExposureSettings exposureLock;  // webcam: exposure / gain / white balance to hold
    std::string screenshot;         // window: save a PNG after --screenshot-after frames, exit
    int screenshotAfter = 10;
    // The fish-eye environment camera (docs/environment.md): a webcam, a video or a session's
    // environment camera, and its calibration (intrinsics, extrinsics, radiometry_to_main).
    std::string envCamera, envCalibration;
    bool estimateLights = false;  // place the environment camera's dominant lights
};

constexpr int kHudWidth = 330;  // pixels, right of the view

// Quality presets of the HUD: VPLs, gather scale (0 = automatic by the canvas width, 1 = full
// resolution), impostor resolution.
struct QualityPreset {
    const char* name;
    int vpls, indirectScale, impostorResolution;
};
constexpr QualityPreset kPresets[] = {
    {"low", 64, 0, 128}, {"medium", 256, 0, 256}, {"high", 1024, 1, 512}};

// What the HUD can show instead of the composite (canvas-size linear buffers, tone-mapped by
// clamping to [0, 1] and sRGB encoding).
struct BufferView {
    const char* name;
    std::optional<render::Resource> resource;  // nullopt: the composite
};
const BufferView kViews[] = {{"composite", std::nullopt},
                             {"L_rv (real + virtual)", render::Resource::LRv},
                             {"L_r (real only)", render::Resource::LR},
                             {"direct L_rv", render::Resource::DirectRv},
                             {"direct L_r", render::Resource::DirectR},
                             {"G-buffer albedo", render::Resource::GBufferAlbedo},
                             {"G-buffer normal", render::Resource::GBufferNormal}};
constexpr int kViewCount = int(sizeof kViews / sizeof kViews[0]);

// A linear RGB float buffer (top row first) shown as sRGB 8-bit BGR.
cv::Mat toneMapForView(const cv::Mat& linearRgb) {
    cv::Mat c;
    cv::min(cv::max(linearRgb, 0.0), 1.0, c);
    cv::Mat out(c.size(), CV_8UC3);
    for (int y = 0; y < c.rows; ++y)
        for (int x = 0; x < c.cols; ++x) {
            const cv::Vec3f v = c.at<cv::Vec3f>(y, x);
            cv::Vec3b& o = out.at<cv::Vec3b>(y, x);
            for (int k = 0; k < 3; ++k) {
                const float l = v[2 - k];  // RGB -> BGR
                const float e =
                    l <= 0.0031308f ? 12.92f * l : 1.055f * std::pow(l, 1 / 2.4f) - 0.055f;
                o[k] = uint8_t(std::lround(std::clamp(e, 0.0f, 1.0f) * 255));
            }
        }
    return out;
}

std::string timestampName(const char* prefix, const char* ext) {
    const std::time_t now = std::time(nullptr);
    char buf[64];
    std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", std::localtime(&now));
    return std::string(prefix) + buf + ext;
}

// The camera: what it is, where its frames come from, how they are paced, and the calibration
// and board found beside a recorded stand-in.
struct CameraInput {
    std::unique_ptr<FrameSource> source;
    LatestFrameCapture::Options pacing;
    std::string description;
    fs::path calibration, board;  // defaults from a session stand-in
    double fps = 30;              // nominal rate (recorded into session.json)
    std::string exposureText = "as recorded (a stand-in)";  // for the HUD
    std::vector<std::string> exposureWarnings;
    std::string calibrationHint, boardHint;  // where a webcam's defaults were looked for
    std::vector<fs::path> inputs;
};

// A recorded stand-in played again from the start whenever it ends (for benchmarks longer than
// the recording).
class LoopingSource final : public FrameSource {
public:
    LoopingSource(std::unique_ptr<FrameSource> first,
                  std::function<std::unique_ptr<FrameSource>()> reopen)
        : current_(std::move(first)), reopen_(std::move(reopen)) {}
    bool read(cv::Mat& bgr) override {
        if (current_->read(bgr)) return true;
        current_ = reopen_();
        return current_->read(bgr);
    }
    int frameCount() const override { return -1; }
    std::string lastProblem() const override { return current_->lastProblem(); }

private:
    std::unique_ptr<FrameSource> current_;
    std::function<std::unique_ptr<FrameSource>()> reopen_;
};

// The first V4L2 node that opens as a capture device; throws saying where it looked.
std::string firstCamera() {
    const std::vector<std::string> nodes = v4l2DeviceNodes();
    std::string tried;
    for (const std::string& n : nodes) {
        try {
            V4l2Device d(n);
            if (!d.modes().empty()) return n;
            tried += "\n  " + n + ": no MJPEG or YUYV mode";
        } catch (const Error& e) {
            tried += "\n  " + n + ": " + e.what();
        }
    }
    throw Error("mirage live: no camera found (looked at /dev/video*: " +
                (nodes.empty() ? std::string("there is none") : "none streams video" + tried) +
                "); plug in a webcam, or let a recorded session or video stand in for one: "
                "--camera SESSION_OR_VIDEO");
}

// The calibration (and board) kept for a camera in cameraConfigDir(), by its model's name.
struct CameraDefaults {
    std::string card;
    fs::path calibration, board;  // where they are looked for
    bool haveCalibration = false, haveBoard = false;
};
CameraDefaults cameraDefaults(const std::string& node) {
    CameraDefaults d;
    V4l2Device dev(node);
    d.card = dev.card();
    const CameraFiles files = cameraFiles(d.card);
    d.calibration = files.calibration;
    d.haveCalibration = fs::exists(d.calibration);
    d.board = files.board();
    d.haveBoard = fs::exists(d.board);
    return d;
}

bool isDeviceName(const std::string& s) {
    if (s.rfind("/dev/video", 0) == 0) return true;
    return !s.empty() &&
           std::all_of(s.begin(), s.end(), [](char c) { return std::isdigit((unsigned char)c); });
}

// A webcam's calibration and board from cameraConfigDir(), or what to do when there is none.
void defaultsFor(const std::string& node, CameraInput& in) {
    const CameraDefaults d = cameraDefaults(node);
    if (d.haveCalibration) in.calibration = d.calibration;
    if (d.haveBoard) in.board = d.board;
    in.calibrationHint = d.haveCalibration
                             ? ""
                             : "looked for " + d.calibration.string() + " (camera '" + d.card +
                                   "'); calibrate it, which saves it there: mirage calibrate "
                                   "--camera " +
                                   node + " --board BOARD.json";
    in.boardHint = d.haveBoard ? ""
                               : "looked for " + d.board.string() + "; copy the board file of " +
                                     "your printed board there";
}

CameraInput openCamera(const LiveArgs& a) {
    CameraInput in;
    std::string device = a.camera;
    if (device.empty()) device = firstCamera();
    if (isDeviceName(device)) {
        CaptureRequest req;
        req.width = a.width;
        req.height = a.height;
        req.fps = a.cameraFps > 0 ? a.cameraFps : 30;
        // Opens the camera and locks its exposure: at the start and after every reconnection
        // (a camera plugged in again starts with automatic exposure).
        auto open = [req, device, lock = a.exposureLock]() {
            auto cam = std::make_unique<V4l2Camera>(device, req);
            cam->lockExposure(lock);
            return cam;
        };
        auto cam = std::make_unique<V4l2Camera>(device, req);
        const ExposureLockReport lock = cam->lockExposure(a.exposureLock);
        in.exposureText = lock.exposureLocked ? "locked" : "AUTOMATIC (not locked)";
        for (const auto& n : lock.notes) in.exposureText += "; " + n;
        in.exposureWarnings = lock.warnings;
        in.fps = cam->mode().fps;
        in.description = "camera " + v4l2DevicePath(device);
        defaultsFor(v4l2DevicePath(device), in);
        if (!cam->modeNote().empty()) in.description += " (" + cam->modeNote() + ")";
        in.source = std::move(cam);
        // A camera paces itself and stamps frames with the driver's monotonic clock; unplugged,
        // it is reopened until it is back ("camera lost" meanwhile).
        in.pacing.sourceClockIsMonotonic = true;
        in.pacing.reopen = [open]() -> std::unique_ptr<FrameSource> { return open(); };
        return in;
    }
    const fs::path p = a.camera;
    if (!fs::exists(p))
        throw FileError(a.camera,
                        "no such camera, session or video (a webcam is /dev/videoN or N)");
    if (fs::is_directory(p) && fs::exists(p / "session.json")) {
        SessionReadReport rr;
        Session s = readSession(p, &rr);
        for (const auto& w : rr.warnings) spdlog::warn("session: {}", w);
        const SessionCamera* main = nullptr;
        for (const auto& c : s.cameras)
            if (c.role == "main") main = &c;
        if (!main) main = &s.cameras.front();
        in.source = openCameraFrames(s, main->name);
        in.fps = s.fps;
        if (!main->calibration.empty()) in.calibration = s.path(main->calibration);
        if (!s.board.empty() && fs::exists(s.path(s.board))) in.board = s.path(s.board);
        in.inputs = sessionInputs(s);
        in.description = "session " + a.camera + " (camera '" + main->name + "')";
        in.pacing.paceBySourceTime = true;  // the session's own frame times
    } else {
        in.source = openFrames(p);
        in.inputs = {p};
        in.description = "video " + a.camera;
        in.pacing.paceBySourceTime = true;  // the video's own clock when it has one
    }
    if (!(in.fps > 0)) in.fps = 30;
    if (a.cameraFps > 0) {
        in.fps = a.cameraFps;
        in.pacing.paceBySourceTime = false;
    }
    in.pacing.paceFps = in.fps;  // frames without a time of their own (a video without a clock)
    if (a.loop) {
        // Played again from the start at its end, paced at its rate (the recorded times would
        // start over).
        in.pacing.paceBySourceTime = false;
        auto reopen = [path = p, isSession = fs::exists(p / "session.json")]() {
            if (!isSession) return openFrames(path);
            Session s = readSession(path);
            const SessionCamera* main = &s.cameras.front();
            for (const auto& c : s.cameras)
                if (c.role == "main") main = &c;
            return openCameraFrames(s, main->name);
        };
        in.source = std::make_unique<LoopingSource>(std::move(in.source), reopen);
        in.description += ", looped";
    }
    return in;
}

// The environment camera of a live session: its frames (a capture thread of its own, paced as
// the main camera's) and its calibration as the renderer's environment camera.
struct EnvironmentInput {
    std::unique_ptr<FrameSource> source;
    LatestFrameCapture::Options pacing;
    render::EnvironmentCameraSetup setup;
    std::string description;
    fs::path calibration;
    std::vector<fs::path> inputs;
    double fps = 30;  // nominal frame rate (pairing with the main camera's frames)
};

EnvironmentInput openEnvironmentCamera(const LiveArgs& a) {
    EnvironmentInput in;
    const std::string& src = a.envCamera;
    fs::path calibration = a.envCalibration;
    if (isDeviceName(src)) {
        CaptureRequest req;
        req.fps = 30;
        auto cam = std::make_unique<V4l2Camera>(src, req);
        // The environment's radiometry is the calibrated ratio to the main camera: its exposure
        // must hold still too.
        const ExposureLockReport lock = cam->lockExposure(a.exposureLock);
        for (const auto& w : lock.warnings) spdlog::warn("live: environment camera: {}", w);
        in.description = "camera " + v4l2DevicePath(src);
        in.fps = cam->mode().fps > 0 ? cam->mode().fps : 30;
        in.source = std::move(cam);
        in.pacing.sourceClockIsMonotonic = true;
    } else {
        const fs::path p = src;
        if (!fs::exists(p))
            throw FileError(src,
                            "no such environment camera, session or video (a webcam is "
                            "/dev/videoN or N)");
        if (fs::is_directory(p) && fs::exists(p / "session.json")) {
            SessionReadReport rr;
            const Session s = readSession(p, &rr);
            const SessionCamera* env = nullptr;
            for (const auto& c : s.cameras)
                if (c.role == "environment") env = &c;
            if (!env)
                throw FileError((p / "session.json").string(),
                                "has no camera with role \"environment\"; record one, or pass a "
                                "video or webcam as --env-camera");
            in.source = openCameraFrames(s, env->name);
            if (s.fps > 0) in.fps = s.fps;
            if (calibration.empty() && !env->calibration.empty())
                calibration = s.path(env->calibration);
            in.inputs = sessionInputs(s);
            in.description = "session " + src + " (camera '" + env->name + "')";
        } else {
            in.source = openFrames(p);
            in.inputs = {p};
            in.description = "video " + src;
        }
        in.pacing.paceBySourceTime = true;
        in.pacing.paceFps = in.fps;
    }
    if (calibration.empty())
        throw Error("mirage live: no calibration for the environment camera " + in.description +
                    "; pass --env-calibration ENV.yaml (its fish-eye calibration with the "
                    "extrinsics from `mirage calibrate`)");
    const CameraCalibration cal = loadCalibration(calibration);
    in.setup = render::EnvironmentCameraSetup::fromCalibration(cal, calibration);
    const std::optional<glm::dvec3> ratio = loadRadiometryToMain(calibration);
    if (!ratio)
        spdlog::warn(
            "live: {} has no radiometry_to_main: the environment camera is taken to "
            "see in the main camera's units (ratio 1)",
            calibration.string());
    in.setup.gain = glm::vec3(ratio.value_or(glm::dvec3(1.0)) / double(a.exposure));
    in.calibration = calibration;
    in.inputs.push_back(calibration);
    return in;
}

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    return v[v.size() / 2];
}

// --list-cameras: every V4L2 node, its modes and controls, and which calibration matches.
void listCameras() {
    const std::vector<std::string> nodes = v4l2DeviceNodes();
    std::printf("calibrations are looked for in %s\n", cameraConfigDir().string().c_str());
    if (nodes.empty()) std::printf("no cameras: /dev/video* holds none\n");
    for (const std::string& n : nodes) {
        try {
            V4l2Device d(n);
            const std::vector<CaptureMode> modes = d.modes();
            std::printf("%s: %s\n", n.c_str(), d.card().c_str());
            for (const CaptureMode& m : modes)
                std::printf("  %s %dx%d at %.2f frames/s\n", pixelFormatName(m.format), m.width,
                            m.height, m.fps);
            if (modes.empty()) std::printf("  no MJPEG or YUYV mode (not usable)\n");
            std::string controls;
            for (const CameraControl& c : d.controls())
                controls += std::string(controls.empty() ? "" : ", ") + cameraControlName(c.id);
            std::printf("  controls: %s\n", controls.empty() ? "none" : controls.c_str());
            const CameraDefaults def = cameraDefaults(n);
            std::printf("  calibration: %s%s\n", def.calibration.string().c_str(),
                        def.haveCalibration ? "" : " (none yet: mirage calibrate ... -o there)");
            std::printf("  board: %s%s\n", def.board.string().c_str(),
                        def.haveBoard ? "" : " (none)");
        } catch (const Error& e) {
            std::printf("%s: not usable: %s\n", n.c_str(), e.what());
        }
    }
}

void runLive(const LiveArgs& a) {
    if (a.listCameras) return listCameras();
    if (a.scene.empty()) throw Error("mirage live: --scene SCENE is required");
    CameraInput cam = openCamera(a);
    const fs::path calibPath = !a.calibration.empty() ? fs::path(a.calibration) : cam.calibration;
    if (calibPath.empty())
        throw Error("mirage live: no calibration for " + cam.description +
                    (cam.calibrationHint.empty() ? "" : ": " + cam.calibrationHint) +
                    "; or pass --calibration CAM.yaml (the file `mirage calibrate` saved for "
                    "this camera)");
    const fs::path boardPath = !a.board.empty() ? fs::path(a.board) : cam.board;
    if (boardPath.empty())
        throw Error("mirage live: no tag board for " + cam.description +
                    (cam.boardHint.empty() ? "" : ": " + cam.boardHint) +
                    "; or pass --board BOARD.json (the board file of the printed board, e.g. "
                    "from `mirage board`)");
    spdlog::info("live: calibration {}, board {}", calibPath.string(), boardPath.string());
    const CameraCalibration calib = loadCalibration(calibPath);
    const int width = calib.intrinsics.width, height = calib.intrinsics.height;
    checkLooksLikeGltf(a.scene);
    Scene scene = loadScene(a.scene);
    if (!scene.hasVirtual())
        spdlog::warn("scene {} has no virtual object: the output will equal the footage", a.scene);
    const tracking::Board board = tracking::Board::load(boardPath);
    tracking::TrackerOptions trackerOptions;
    trackerOptions.features.enabled = !a.boardOnly;
    tracking::Tracker tracker(board, calib.intrinsics, trackerOptions);
    // Where the virtual objects stand: the saved placement (moves within the board's plane).
    const fs::path placementFile =
        a.placement.empty() ? placementPath(a.scene) : fs::path(a.placement);
    ScenePlacement placement = loadPlacement(placementFile).value_or(ScenePlacement{});
    const PlacementPlane plane = boardPlane(board);
    if (!placement.isIdentity())
        spdlog::info(
            "live: placement from {}: moved {:.3f}, {:.3f} m, turned {:.1f} deg, scale {:.3f}",
            placementFile.string(), placement.moveU, placement.moveV, placement.turnDeg,
            placement.scale);
    auto placedScene = [&](const ScenePlacement& p) {
        Scene placed = scene;
        applyPlacement(placed, p, plane);
        return placed;
    };
    // The scene as placed for in-place moves, in every frame of a drag: copied once (meshes,
    // textures), then only its node matrices are reset and placed again.
    Scene moving = scene;
    auto movedScene = [&](const ScenePlacement& p) -> const Scene& {
        moving.nodes = scene.nodes;
        applyPlacement(moving, p, plane);
        return moving;
    };

    std::optional<EnvironmentInput> envCam;
    if (!a.envCamera.empty()) {
        envCam = openEnvironmentCamera(a);
        spdlog::info("live: environment camera {} (calibration {})", envCam->description,
                     envCam->calibration.string());
    } else if (!a.envCalibration.empty()) {
        throw Error(
            "mirage live: --env-calibration without --env-camera; name the environment "
            "camera (a webcam, a video or a session) with --env-camera");
    } else if (a.estimateLights) {
        throw Error(
            "mirage live: --estimate-lights finds the lights in the environment camera's "
            "frames; name the environment camera with --env-camera");
    }
    // Lights found in the environment camera's frames, as many as light estimation reports
    // within the renderer's light budget.
    const int environmentLights =
        a.estimateLights ? std::min(render::LightEstimationOptions{}.maxLights,
                                    render::kMaxLights - int(scene.lightInstances().size()))
                         : 0;
    if (a.estimateLights && environmentLights <= 0)
        throw Error(fmt::format(
            "mirage live --estimate-lights: scene {} already has {} lights, the real-time "
            "renderer's limit; remove one",
            a.scene, render::kMaxLights));

    // Outputs, checked before any work (as replay's).
    OutputRule rule{cam.inputs, a.force, "mirage live"};
    if (envCam) rule.inputs.insert(rule.inputs.end(), envCam->inputs.begin(), envCam->inputs.end());
    rule.inputs.push_back(a.scene);
    rule.inputs.push_back(calibPath);
    rule.inputs.push_back(boardPath);
    std::optional<OutputFile> videoOut, csvOut;
    fs::path out, csvPath;
    bool mkv = false;
    if (!a.output.empty()) {
        out = a.output;
        mkv = isVideoOutput(out, "mirage live");
        if (mkv) {
            videoOut.emplace(out, OutputOrigin::Named, rule);
            csvPath = fs::path(out).replace_extension(".csv");
        } else {
            checkOutput(out, OutputOrigin::Named, rule, /*outIsFolder=*/true);
            fs::create_directories(out);
            csvPath = out / "frames.csv";
        }
        csvOut.emplace(csvPath, OutputOrigin::Derived, rule);
    }
    if (!a.record.empty()) {
        checkOutput(a.record, OutputOrigin::Named, rule, true);
        LiveRecording::checkFolder(a.record);
    }

    gl::ContextOptions copt;
    copt.width = width + kHudWidth;  // the view, and the HUD beside it
    copt.height = std::max(height, 560);
    copt.title = "mirage live";
    gl::Context ctx = a.headless ? gl::Context::headless(copt) : gl::Context::window(copt);
    int preset = 1;  // medium: the defaults
    // A renderer for the scene as placed. Built anew when the quality or the effects change;
    // a new placement moves the objects in place (Renderer::updateTransforms). Either way every
    // pass that depends on where things stand (shadows, VPLs, imperfect shadow maps, caustics,
    // impostors) runs again in the next frame; while nothing changes the camera-independent
    // passes are reused.
    int vpls = a.vpls;  // --vpls, until a preset is chosen
    // The effects as switched (--off, then the HUD's checkboxes): RendererOptions' switches.
    render::RendererOptions effects;
    switchEffectsOff(a.effectsOff, effects);
    auto makeRenderer = [&] {
        render::RendererOptions ropt = effects;
        ropt.vplCount = vpls;
        ropt.indirectScale = kPresets[preset].indirectScale;
        ropt.impostorResolution = kPresets[preset].impostorResolution;
        ropt.exposure = a.exposure;
        ropt.environmentLights = environmentLights;
        // The HUD's direct-light views need the direct light apart in frames with VPLs (two
        // more canvas targets); a headless run shows no view and does not pay for them.
        ropt.keepDirectLight = !a.headless;
        return std::make_unique<render::Renderer>(placedScene(placement), calib.intrinsics, ropt);
    };
    std::unique_ptr<render::Renderer> renderer = makeRenderer();
    auto compositor = std::make_unique<FrameCompositor>(*renderer, &tracker);
    // The environment camera's newest frame lights the scene from the next render on; a renderer
    // built anew (quality, placement) gets the camera and the last frame again.
    cv::Mat envFrame;
    double envTime = 0;
    auto attachEnvironment = [&] {
        if (!envCam) return;
        renderer->setEnvironmentCamera(envCam->setup);
        if (!envFrame.empty()) renderer->updateEnvironment(envFrame, envTime);
    };
    attachEnvironment();

    std::unique_ptr<MatroskaWriter> video;
    if (mkv) video = std::make_unique<MatroskaWriter>(videoOut->temp(), cam.fps, a.jpegQuality);
    std::ofstream csv;
    const std::vector<std::string> passes = renderer->passNames();
    if (csvOut) {
        csv.open(csvOut->temp());
        if (!csv) throw FileError(csvPath.string(), "cannot create the timing CSV");
        csv << "frame,t,state,reason,camera_frame,dropped,driver_dropped,env_age_ms,tracking_ms";
        for (const std::string& p : passes) csv << "," << p << "_ms";
        csv << ",gpu_ms,readback_ms,frame_ms,latency_ms,tx,ty,tz,qw,qx,qy,qz\n";
    }
    std::unique_ptr<LiveRecording> recording;
    bool recordNameUsed = false;
    // With an environment camera every recorded row holds both cameras' frames: main frames
    // processed before its first frame arrived are not recorded (counted here, said at the end).
    int recordWaitsForEnv = 0;
    cv::Mat envLatest;  // the environment camera's newest frame as delivered, and its time
    double envLatestTime = 0;
    auto startRecording = [&] {
        fs::path dir = !a.record.empty() && !recordNameUsed ? fs::path(a.record)
                                                            : fs::path(timestampName("live-", ""));
        recordNameUsed = true;
        LiveRecording::Options ro;
        ro.fps = cam.fps;
        ro.jpegQuality = a.jpegQuality;
        if (envCam) ro.environmentCalibration = envCam->calibration;
        recording = std::make_unique<LiveRecording>(dir, calibPath, boardPath, ro);
        recordWaitsForEnv = 0;
        spdlog::info("live: recording into {}{}", dir.string(),
                     envCam ? " (with the environment camera)" : "");
    };
    auto stopRecording = [&] {
        if (!recording) return;
        recording->close();
        if (recordWaitsForEnv > 0)
            spdlog::warn(
                "live: the first {} processed frames were not recorded: the environment camera "
                "had delivered no frame yet",
                recordWaitsForEnv);
        spdlog::info(
            "live: recorded {} frames into {} (replay: mirage replay {} --scene {} --poses "
            "{}/poses.csv -o OUT)",
            recording->frames(), recording->dir().string(), recording->dir().string(), a.scene,
            recording->dir().string());
        recording.reset();
    };
    if (!a.record.empty()) startRecording();

    spdlog::info("live: {} -> {} ({}x{}); tracking on {}", cam.description,
                 a.headless ? "headless" : "window", width, height, boardPath.string());
    std::optional<ImGuiScope> imgui;
    if (!a.headless) imgui.emplace(ctx.glfwWindow());
    gl::Texture shown;  // what the window shows: the composite or a buffer, RGBA8
    cv::Mat shownRgba;
    auto show = [&](const cv::Mat& bgr) {
        if (bgr.empty()) return;
        if (shown.id() == 0) {
            shown = gl::Texture::create2D("live view", bgr.cols, bgr.rows, GL_RGBA8);
            shown.setFilter(GL_LINEAR, GL_LINEAR);
        }
        cv::cvtColor(bgr, shownRgba, cv::COLOR_BGR2RGBA);
        shown.upload(GL_RGBA, GL_UNSIGNED_BYTE, shownRgba.data);
    };

    installStopSignals();
    LatestFrameCapture capture(std::move(cam.source), cam.pacing);
    std::optional<LatestFrameCapture> envCapture;
    if (envCam) envCapture.emplace(std::move(envCam->source), envCam->pacing);
    bool envEnded = false;
    std::string envProblem;  // the last environment frame's problem (warned once)
    // Age of the environment frame lighting the current frame (main capture time minus the
    // environment's, ms; empty in the CSV without an environment camera).
    double envAgeMs = std::numeric_limits<double>::quiet_NaN();
    std::vector<double> latencies;
    int processed = 0;
    const auto tStart = Clock::now();
    bool windowClosed = false, reportedLost = false;
    bool paused = false, hideVirtual = false;
    int view = 0;
    bool placementPending = false;        // moved, not yet saved
    bool needsRebuild = false;            // moved, but not in place (a translucent object)
    std::optional<glm::dvec3> dragStart;  // where a left-drag started on the board plane
    ScenePlacement dragFrom;
    auto placementChangedAt = Clock::now();
    double fpsEma = 0, lastLatencyMs = 0;
    auto lastFrameAt = Clock::now();
    CompositedFrame last;  // the last processed frame, for the HUD
    std::string viewProblem;
    while (!stopRequested() && !windowClosed && (a.maxFrames < 0 || processed < a.maxFrames)) {
        CapturedFrame f;
        bool got = false;
        if (!paused) {
            // The window redraws at most about every 15 ms while it waits for a frame (a frame
            // that arrives ends the wait at once), so the HUD stays responsive without spinning.
            got = capture.next(f, a.headless ? 0.1 : 0.015);
            if (!got && capture.ended()) break;
        } else {
            std::this_thread::sleep_for(std::chrono::milliseconds(15));
        }
        const bool lost = capture.state() == LatestFrameCapture::State::Lost;
        if (lost && !reportedLost)
            spdlog::warn("live: camera lost: {}; waiting for it to come back",
                         capture.lostReason());
        if (!lost && reportedLost) spdlog::info("live: camera back");
        reportedLost = lost;
        if (got && !f.bgr.empty() && (f.bgr.cols != width || f.bgr.rows != height))
            throw Error(fmt::format(
                "mirage live: {} delivers {}x{} frames but the calibration {} is for {}x{}; use "
                "the calibration of this camera at this size (or ask the camera for {}x{})",
                cam.description, f.bgr.cols, f.bgr.rows, calibPath.string(), width, height, width,
                height));
        if (got && envCapture) {
            // The environment frame nearest in time to this one (both clocks are
            // CLOCK_MONOTONIC): the newest in the slot, or, when that is more than half an
            // environment frame older, the next one if it comes within that half frame (the
            // cameras run side by side; the main camera sets the pace).
            CapturedFrame ef;
            bool haveEnv = envCapture->next(ef, 0.0) && !ef.bgr.empty();
            const double newest = haveEnv ? ef.captureSeconds : envTime;
            const double halfPeriod = 0.5 / envCam->fps;
            if (!envCapture->ended() &&
                (newest < f.captureSeconds - halfPeriod || (!haveEnv && envFrame.empty()))) {
                CapturedFrame later;
                if (envCapture->next(later, std::min(halfPeriod, 0.05)) && !later.bgr.empty()) {
                    ef = std::move(later);
                    haveEnv = true;
                }
            }
            if (haveEnv) {
                envLatest = ef.bgr;
                envLatestTime = ef.captureSeconds;
                try {
                    renderer->updateEnvironment(ef.bgr, ef.captureSeconds);
                    envFrame = ef.bgr;
                    envTime = ef.captureSeconds;
                } catch (const Error& e) {
                    // Once per distinct problem: a wrong calibration fails every frame alike.
                    if (envProblem != e.what()) {
                        envProblem = e.what();
                        spdlog::warn("live: environment frames not used: {}", envProblem);
                    }
                }
            } else if (!envEnded && envCapture->ended()) {
                envEnded = true;
                spdlog::warn(
                    "live: the environment camera ended ({}); lighting stays with its "
                    "last frame",
                    envCapture->error().empty() ? "end of its stream" : envCapture->error());
            }
            envAgeMs = envFrame.empty() ? std::numeric_limits<double>::quiet_NaN()
                                        : (f.captureSeconds - envTime) * 1e3;
        }
        if (got) {
            const auto t0 = Clock::now();
            CompositedFrame cf =
                compositor->process(f.bgr, f.captureSeconds, f.problem, std::nullopt, !hideVirtual);
            if (f.bgr.empty()) spdlog::warn("live: {}", cf.pose.reason);
            if (!cf.image.empty()) {
                if (video) video->append(cf.image, f.captureSeconds);
                if (!out.empty() && !mkv)
                    writeBgr8(out / cv::format("frame_%06d.png", processed), cf.image);
                if (!a.headless) {
                    viewProblem.clear();
                    cv::Mat img = cf.image;
                    if (kViews[view].resource && cf.report) {
                        try {
                            img = toneMapForView(renderer->readBuffer(*kViews[view].resource));
                        } catch (const Error& e) {
                            viewProblem = e.what();
                        }
                    }
                    show(img);
                }
            }
            // Written (headless) or uploaded for display: the end of the capture-to-display
            // latency (the window's swap follows below).
            const double latencyMs = (steadySeconds() - f.captureSeconds) * 1e3;
            latencies.push_back(latencyMs);
            lastLatencyMs = latencyMs;
            if (recording && !f.bgr.empty()) {
                if (!recording->hasEnvironment())
                    recording->append(f.bgr, f.captureSeconds, cf.pose);
                else if (envLatest.empty())
                    ++recordWaitsForEnv;
                else
                    // The newest environment frame delivered, used or not: a frame the renderer
                    // refused is refused again in replay with the same calibration.
                    recording->append(f.bgr, f.captureSeconds, cf.pose, envLatest, envLatestTime);
            }
            if (csv.is_open()) {
                csv << processed << "," << exactDecimal(f.captureSeconds) << ","
                    << csvField(cf.pose.state) << "," << csvField(cf.pose.reason) << ","
                    << f.sequence << "," << f.droppedBefore << "," << f.deviceDroppedBefore << ",";
                if (std::isfinite(envAgeMs)) csv << envAgeMs;
                csv << "," << cf.trackingMs;
                for (const std::string& p : passes) {
                    auto it = cf.passMs.find(p);
                    csv << "," << (it == cf.passMs.end() ? 0.0 : it->second);
                }
                csv << "," << cf.gpuMs << "," << cf.readbackMs << "," << msSince(t0) << ","
                    << latencyMs;
                if (cf.pose.pose) {
                    const Pose& p = *cf.pose.pose;
                    for (double v : {p.translation.x, p.translation.y, p.translation.z,
                                     p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z})
                        csv << "," << exactDecimal(v);
                } else {
                    csv << ",,,,,,,";
                }
                csv << "\n";
                csv.flush();
            }
            const double dt = msSince(lastFrameAt) * 1e-3;
            lastFrameAt = Clock::now();
            if (processed > 0 && dt > 0) fpsEma = fpsEma == 0 ? 1 / dt : 0.8 * fpsEma + 0.2 / dt;
            last = std::move(cf);
            last.image.release();
            ++processed;
        }
        if (a.headless) continue;

        // Window: the view, the HUD, the keys.
        ctx.pollEvents();
        windowClosed = ctx.shouldClose();
        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        int fbw = 0, fbh = 0;
        glfwGetFramebufferSize(ctx.glfwWindow(), &fbw, &fbh);
        // The view fills the space left of the HUD, keeping the camera's aspect ratio.
        const float scale = std::min(float(std::max(fbw - kHudWidth, 1)) / float(width),
                                     float(fbh) / float(height));
        if (shown.id() != 0)
            ImGui::GetBackgroundDrawList()->AddImage(
                reinterpret_cast<ImTextureID>(static_cast<uintptr_t>(shown.id())), {0, 0},
                {float(width) * scale, float(height) * scale});
        bool screenshot = false, toggleRecord = false;
        const ImGuiIO& io = ImGui::GetIO();
        if (!io.WantCaptureKeyboard) {
            if (ImGui::IsKeyPressed(GLFW_KEY_P, false)) paused = !paused;
            if (ImGui::IsKeyPressed(GLFW_KEY_R, false)) toggleRecord = true;
            if (ImGui::IsKeyPressed(GLFW_KEY_S, false)) screenshot = true;
            if (ImGui::IsKeyPressed(GLFW_KEY_H, false)) hideVirtual = !hideVirtual;
            if (ImGui::IsKeyPressed(GLFW_KEY_B, false)) view = (view + 1) % kViewCount;
            if (ImGui::IsKeyPressed(GLFW_KEY_ESCAPE, false)) windowClosed = true;
            // Placement, snapped to the board plane: 1 cm steps, 5 degree turns, 5 % scale.
            ScenePlacement p = placement;
            if (ImGui::IsKeyPressed(GLFW_KEY_LEFT)) p.moveU -= 0.01;
            if (ImGui::IsKeyPressed(GLFW_KEY_RIGHT)) p.moveU += 0.01;
            if (ImGui::IsKeyPressed(GLFW_KEY_UP)) p.moveV -= 0.01;
            if (ImGui::IsKeyPressed(GLFW_KEY_DOWN)) p.moveV += 0.01;
            if (ImGui::IsKeyPressed(GLFW_KEY_Q)) p.turnDeg += 5;
            if (ImGui::IsKeyPressed(GLFW_KEY_E)) p.turnDeg -= 5;
            if (ImGui::IsKeyPressed(GLFW_KEY_EQUAL) || ImGui::IsKeyPressed(GLFW_KEY_KP_ADD))
                p.scale *= 1.05;
            if (ImGui::IsKeyPressed(GLFW_KEY_MINUS) || ImGui::IsKeyPressed(GLFW_KEY_KP_SUBTRACT))
                p.scale /= 1.05;
            if (ImGui::IsKeyPressed(GLFW_KEY_0, false)) p = ScenePlacement{};
            // Left-drag on the view moves the objects with the point under the mouse (on the
            // board plane, seen with the last tracked pose).
            const ImVec2 mouse = io.MousePos;
            const glm::dvec2 px(mouse.x / scale, mouse.y / scale);
            if (ImGui::IsMouseClicked(0) && !io.WantCaptureMouse && last.pose.pose &&
                mouse.x < float(width) * scale) {
                dragStart = pixelOnPlane(calib.intrinsics, *last.pose.pose, px, plane);
                dragFrom = placement;
            }
            if (!ImGui::IsMouseDown(0)) dragStart.reset();
            if (dragStart && last.pose.pose && ImGui::IsMouseDragging(0)) {
                if (const auto hit = pixelOnPlane(calib.intrinsics, *last.pose.pose, px, plane)) {
                    const glm::dvec2 m = inPlaneMove(*dragStart, *hit, plane);
                    // Snapped to whole millimetres on the board.
                    p.moveU = dragFrom.moveU + std::round(m.x * 1000) / 1000;
                    p.moveV = dragFrom.moveV + std::round(m.y * 1000) / 1000;
                }
            }
            if (!(p == placement)) {
                placement = p;
                placementChangedAt = Clock::now();
                placementPending = true;
                // The objects follow in the next frame: moved in place (shadows, indirect light,
                // caustics and impostors redone in that frame), or, for a translucent object
                // whose voxel number map lies in the world, by a new renderer once the keys rest.
                needsRebuild = needsRebuild || !renderer->updateTransforms(movedScene(placement));
            }
        }
        ImGui::SetNextWindowPos({float(fbw - kHudWidth), 0});
        ImGui::SetNextWindowSize({float(kHudWidth), float(fbh)});
        ImGui::Begin(
            "mirage live", nullptr,
            ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
        const ImVec4 red(1, 0.4f, 0.4f, 1), green(0.4f, 1, 0.4f, 1), amber(1, 0.85f, 0.3f, 1);
        if (lost) ImGui::TextColored(red, "CAMERA LOST: %s", capture.lostReason().c_str());
        ImGui::Text("%.1f frames/s | latency %.0f ms", fpsEma, lastLatencyMs);
        ImGui::Text("dropped %lld (driver %lld)", static_cast<long long>(capture.dropped()),
                    static_cast<long long>(capture.deviceDropped()));
        const std::string& st = last.pose.state;
        ImGui::TextColored(
            st == "ok"   ? green
            : st.empty() ? amber
                         : red,
            "tracking: %s%s", st.empty() ? "waiting for a frame" : st.c_str(),
            last.trackingMode.empty() ? "" : (" (" + last.trackingMode + ")").c_str());
        ImGui::PushTextWrapPos(0);
        if (!last.pose.reason.empty()) ImGui::TextWrapped("%s", last.pose.reason.c_str());
        ImGui::TextWrapped("exposure: %s", cam.exposureText.c_str());
        if (envCam)
            ImGui::TextWrapped("environment: %s%s", envCam->description.c_str(),
                               envFrame.empty() ? ", waiting for a frame"
                               : envEnded       ? ", ended (its last frame lights)"
                               : std::isfinite(envAgeMs)
                                   ? cv::format(", frame %.0f ms older", envAgeMs).c_str()
                                   : "");
        for (const auto& w : cam.exposureWarnings) ImGui::TextColored(amber, "%s", w.c_str());
        ImGui::PopTextWrapPos();
        ImGui::Separator();
        if (last.report && ImGui::BeginTable("passes", 2, ImGuiTableFlags_SizingFixedFit)) {
            for (const auto& pr : last.report->passes) {
                ImGui::TableNextRow();
                ImGui::TableNextColumn();
                ImGui::TextUnformatted(pr.name.c_str());
                ImGui::TableNextColumn();
                if (pr.ran)
                    ImGui::Text("%6.2f ms", pr.gpuMs);
                else
                    ImGui::TextDisabled("%s", pr.reused ? "reused" : "off");
            }
            ImGui::EndTable();
            ImGui::Text("GPU %.1f ms", last.gpuMs);
        }
        ImGui::Separator();
        int newPreset = preset;
        if (ImGui::BeginCombo("quality", kPresets[preset].name)) {
            for (int i = 0; i < 3; ++i)
                if (ImGui::Selectable(kPresets[i].name, i == preset)) newPreset = i;
            ImGui::EndCombo();
        }
        if (ImGui::BeginCombo("view (B)", kViews[view].name)) {
            for (int i = 0; i < kViewCount; ++i)
                if (ImGui::Selectable(kViews[i].name, i == view)) view = i;
            ImGui::EndCombo();
        }
        if (!viewProblem.empty()) ImGui::TextColored(amber, "%s", viewProblem.c_str());
        // Effects on/off: each switch rebuilds the renderer (its passes leave the frame graph,
        // and the pass table above says why they did not run).
        bool effectsChanged = false;
        if (ImGui::CollapsingHeader("effects")) {
            for (const EffectSwitch& e : kEffectSwitches) {
                bool on = effects.*e.member;
                if (ImGui::Checkbox(e.label, &on)) {
                    effects.*e.member = on;
                    effectsChanged = true;
                    spdlog::info("live: {} {}", e.name, on ? "on" : "off");
                }
            }
        }
        ImGui::Text("placement %+.2f %+.2f m, %+.0f deg, x%.2f%s", placement.moveU, placement.moveV,
                    placement.turnDeg, placement.scale, placementPending ? " (moving)" : "");
        ImGui::TextDisabled("drag or arrows move, Q/E turn, +/- scale, 0 reset");
        ImGui::Checkbox("pause (P)", &paused);
        ImGui::SameLine();
        ImGui::Checkbox("hide virtual (H)", &hideVirtual);
        if (ImGui::Button(recording ? "stop recording (R)" : "record (R)")) toggleRecord = true;
        ImGui::SameLine();
        if (ImGui::Button("screenshot (S)")) screenshot = true;
        if (recording)
            ImGui::TextColored(red, "REC %s: %d frames", recording->dir().string().c_str(),
                               recording->frames());
        ImGui::End();
        ImGui::Render();
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glViewport(0, 0, fbw, fbh);
        glClearColor(0, 0, 0, 1);
        glClear(GL_COLOR_BUFFER_BIT);
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
        if (!a.screenshot.empty() && processed >= a.screenshotAfter) {
            saveWindowPng(a.screenshot, ctx.glfwWindow());
            windowClosed = true;
        }
        if (screenshot) saveWindowPng(timestampName("mirage-live-", ".png"), ctx.glfwWindow());
        ctx.swapBuffers();
        if (toggleRecord) {
            try {
                if (recording)
                    stopRecording();
                else
                    startRecording();
            } catch (const Error& e) {
                // A recording that cannot start (a folder in the way, a full disk) must not end
                // the session: say why and go on.
                spdlog::warn("live: {}", e.what());
                recording.reset();
            }
        }
        // A placement change is saved beside the scene once the keys rest for 0.3 s; a move that
        // could not be made in place is applied then by a new renderer (a rebuild takes about a
        // second on llvmpipe).
        if (placementPending && msSince(placementChangedAt) > 300 && !dragStart) {
            placementPending = false;
            if (needsRebuild) {
                needsRebuild = false;
                renderer = makeRenderer();
                compositor = std::make_unique<FrameCompositor>(*renderer, &tracker);
                attachEnvironment();
                last.report = nullptr;
            }
            try {
                savePlacement(placementFile, placement);
                spdlog::info("live: placement saved to {}", placementFile.string());
            } catch (const Error& e) {
                spdlog::warn("live: placement not saved: {}", e.what());
            }
        }
        if (newPreset != preset || effectsChanged) {
            // A new renderer with the preset's options and the effects as switched; the
            // temporal history starts again.
            if (newPreset != preset) {
                preset = newPreset;
                vpls = kPresets[preset].vpls;
                spdlog::info("live: quality {}", kPresets[preset].name);
            }
            renderer = makeRenderer();
            compositor = std::make_unique<FrameCompositor>(*renderer, &tracker);
            attachEnvironment();
            last.report = nullptr;
        }
    }
    const std::string captureError = capture.error();
    capture.stop();
    if (envCapture) envCapture->stop();
    const double seconds = msSince(tStart) * 1e-3;
    if (video) video->close();
    if (csv.is_open()) closeChecked(csv, csvPath);
    if (videoOut) videoOut->commit();
    if (csvOut) csvOut->commit();
    stopRecording();
    restoreStopSignals();
    spdlog::info(
        "live: {} frames in {:.1f} s ({:.1f} frames/s); camera delivered {}, dropped {} while "
        "processing was busy (the driver dropped {}); median capture-to-display latency {:.0f} "
        "ms; camera reconnected {} times",
        processed, seconds, processed / std::max(seconds, 1e-9), capture.delivered(),
        capture.dropped(), capture.deviceDropped(), median(latencies), capture.reconnections());
    if (!captureError.empty()) throw Error("mirage live: " + captureError);
    if (stopRequested()) commandExitCode() = 128 + stopSignal();
}

const CommandRegistrar reg("live", [](CLI::App& parent) {
    auto args = std::make_shared<LiveArgs>();
    auto* cmd = parent.add_subcommand(
        "live", "Live AR session: track a camera, composite the scene's virtual objects, show it");
    cmd->add_option("--camera", args->camera,
                    "/dev/videoN (or N) for a webcam (default: the first camera); a session "
                    "folder or a video stands in for a camera, paced at its frame rate");
    cmd->add_option("--env-camera", args->envCamera,
                    "The fish-eye environment camera that lights the scene every frame: "
                    "/dev/videoN (or N), a video, or a session folder (its environment camera)");
    cmd->add_option("--env-calibration", args->envCalibration,
                    "The environment camera's calibration (fish-eye intrinsics, extrinsics, "
                    "radiometry_to_main; default for a session: the one session.json names)")
        ->check(CLI::ExistingFile);
    cmd->add_flag("--estimate-lights", args->estimateLights,
                  "Find the dominant lights of each environment-camera frame and place them as "
                  "shadow-casting real directional lights (their regions taken out of the "
                  "environment light)");
    cmd->add_option("--scene", args->scene,
                    "Scene (.gltf/.glb) with real proxies and virtual objects (required)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--placement", args->placement,
                    "Where the virtual objects stand (default: SCENE.placement.json if it exists; "
                    "the window's keys move them and save it there)");
    cmd->add_flag("--list-cameras", args->listCameras,
                  "List the cameras, their modes and controls, and which calibration matches");
    cmd->add_option("--calibration", args->calibration,
                    "The camera's calibration (OpenCV YAML from `mirage calibrate`; default: the "
                    "stand-in session's, or a webcam's in the camera folder: --list-cameras)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--board", args->board,
                    "Tag board file (default: the stand-in session's, or beside a webcam's "
                    "calibration)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--camera-fps", args->cameraFps,
                    "Frame rate asked of a webcam, or at which a stand-in delivers frames "
                    "(default: 30; a session's own times; a video's own clock, else 30)")
        ->check(finiteIn(0, 1000, true));
    cmd->add_option("--width", args->width, "Frame width asked of a webcam")
        ->capture_default_str()
        ->check(wholeIn(16, 16384));
    cmd->add_option("--height", args->height, "Frame height asked of a webcam")
        ->capture_default_str()
        ->check(wholeIn(16, 16384));
    cmd->add_flag("--camera-loop", args->loop,
                  "Play a stand-in session or video again from the start when it ends");
    cmd->add_flag("--headless", args->headless, "No window (EGL): for tests and benchmarks");
    cmd->add_flag("--board-only", args->boardOnly,
                  "Track the board's tags only, no natural features (docs/tracking.md)");
    cmd->add_option("--frames", args->maxFrames, "Stop after N processed frames")
        ->check(wholeIn(-1, 100000000));
    cmd->add_option("-o,--output", args->output,
                    "Write the composites: OUT.mkv (MJPEG video) or a folder of PNG frames, with "
                    "a per-frame CSV beside it");
    cmd->add_option("--off", args->effectsOff,
                    "Start with these effects off (comma-separated, as `mirage bench` names "
                    "them; the HUD switches them): " +
                        effectSwitchNames())
        ->delimiter(',')
        ->check(effectSwitchName());
    cmd->add_option("--record", args->record,
                    "Record the session (the camera's frames and the live poses) into this new "
                    "folder; replay it with `mirage replay`");
    cmd->add_option("--vpls", args->vpls, "Virtual point lights per frame")
        ->check(wholeIn(0, 16384));
    cmd->add_option("--exposure", args->exposure, "Rendered radiance -> camera linear units")
        ->check(finiteIn(0, 1e6, true));
    cmd->add_flag("--force", args->force, "Replace an existing CSV beside the output");
    cmd->add_option("--screenshot", args->screenshot,
                    "Window: save a PNG of the window after --screenshot-after frames, then exit");
    cmd->add_option("--screenshot-after", args->screenshotAfter,
                    "Window: frames to process before --screenshot")
        ->capture_default_str()
        ->check(wholeIn(1, 100000000));
    auto setOpt = [](std::optional<int64_t>& o) { return [&o](int64_t v) { o = v; }; };
    cmd->add_option_function<int64_t>("--camera-exposure", setOpt(args->exposureLock.exposure),
                                      "Webcam exposure time (V4L2 units of 100 us; default: "
                                      "where automatic exposure settled, then locked)")
        ->check(wholeIn(1, 1000000));
    cmd->add_option_function<int64_t>("--camera-gain", setOpt(args->exposureLock.gain),
                                      "Webcam gain (device units; default: locked where it was)")
        ->check(wholeIn(0, 1000000));
    cmd->add_option_function<int64_t>(
           "--white-balance", setOpt(args->exposureLock.whiteBalanceK),
           "Webcam white balance, kelvin (default: locked where automatic white balance was)")
        ->check(wholeIn(1000, 20000));
    cmd->callback([args] { runLive(*args); });
});

}  // namespace
}  // namespace mirage::app
