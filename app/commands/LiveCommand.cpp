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
#include <cstdio>
#include <fstream>
#include <optional>

#include "app/Command.h"
#include "app/FrameCompositor.h"
#include "app/InputChecks.h"
#include "app/NumberChecks.h"
#include "core/Csv.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/camera/CalibrationFile.h"
#include "core/capture/CameraControls.h"
#include "core/capture/CaptureFormat.h"
#include "core/capture/LatestFrameCapture.h"
#include "core/capture/LiveRecording.h"
#include "core/capture/V4l2Camera.h"
#include "core/capture/V4l2Device.h"
#include "core/gl/Context.h"
#include "core/image/ImageIO.h"
#include "core/scene/Scene.h"
#include "core/session/MatroskaWriter.h"
#include "core/session/Session.h"
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
    double cameraFps = 0;  // 0: the stand-in's own rate
    int width = 640, height = 480;
    int maxFrames = -1;
    int vpls = 256;
    float exposure = 1.0f;
    int jpegQuality = 92;
    bool headless = false;
    bool force = false;
    ExposureSettings exposureLock;  // webcam: exposure / gain / white balance to hold
};

// The camera: what it is, where its frames come from, how they are paced, and the calibration
// and board found beside a recorded stand-in.
struct CameraInput {
    std::unique_ptr<FrameSource> source;
    LatestFrameCapture::Options pacing;
    std::string description;
    fs::path calibration, board;  // defaults from a session stand-in
    double fps = 30;              // nominal rate (recorded into session.json)
    std::vector<fs::path> inputs;
};

bool isDeviceName(const std::string& s) {
    if (s.rfind("/dev/video", 0) == 0) return true;
    return !s.empty() &&
           std::all_of(s.begin(), s.end(), [](char c) { return std::isdigit((unsigned char)c); });
}

CameraInput openCamera(const LiveArgs& a) {
    CameraInput in;
    if (a.camera.empty())
        throw Error(
            "mirage live: name the camera with --camera: /dev/videoN (or N) for a webcam, or a "
            "recorded session folder or video to stand in for one");
    if (isDeviceName(a.camera)) {
        CaptureRequest req;
        req.width = a.width;
        req.height = a.height;
        req.fps = a.cameraFps > 0 ? a.cameraFps : 30;
        // Opens the camera and locks its exposure: at the start and after every reconnection
        // (a camera plugged in again starts with automatic exposure).
        auto open = [req, device = a.camera, lock = a.exposureLock]() {
            auto cam = std::make_unique<V4l2Camera>(device, req);
            cam->lockExposure(lock);
            return cam;
        };
        auto cam = open();
        in.fps = cam->mode().fps;
        in.description = "camera " + v4l2DevicePath(a.camera);
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
    if (a.cameraFps > 0) {
        in.fps = a.cameraFps;
        in.pacing.paceFps = a.cameraFps;
        in.pacing.paceBySourceTime = false;
    } else if (!in.source->lastTimestamp() && in.fps <= 0) {
        in.fps = 30;
    }
    return in;
}

bool isVideoOutput(const fs::path& out) {
    std::string ext = out.extension().string();
    for (char& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    if (ext == ".mkv") return true;
    if (ext.empty() || fs::is_directory(out)) return false;
    throw Error("mirage live: output '" + out.string() +
                "' must end in .mkv (MJPEG video) or be a folder (no extension) for PNG frames");
}

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    return v[v.size() / 2];
}

void runLive(const LiveArgs& a) {
    CameraInput cam = openCamera(a);
    const fs::path calibPath = !a.calibration.empty() ? fs::path(a.calibration) : cam.calibration;
    if (calibPath.empty())
        throw Error("mirage live: no calibration for " + cam.description +
                    "; pass --calibration CAM.yaml (the file `mirage calibrate` saved for this "
                    "camera; calibrate it first if there is none)");
    const fs::path boardPath = !a.board.empty() ? fs::path(a.board) : cam.board;
    if (boardPath.empty())
        throw Error("mirage live: no tag board for " + cam.description +
                    "; pass --board BOARD.json (the board file of the printed board, e.g. from "
                    "`mirage board`)");
    const CameraCalibration calib = loadCalibration(calibPath);
    const int width = calib.intrinsics.width, height = calib.intrinsics.height;
    checkLooksLikeGltf(a.scene);
    Scene scene = loadScene(a.scene);
    if (!scene.hasVirtual())
        spdlog::warn("scene {} has no virtual object: the output will equal the footage", a.scene);
    tracking::Tracker tracker(tracking::Board::load(boardPath), calib.intrinsics);

    // Outputs, checked before any work (as replay's).
    OutputRule rule{cam.inputs, a.force, "mirage live"};
    rule.inputs.push_back(a.scene);
    rule.inputs.push_back(calibPath);
    rule.inputs.push_back(boardPath);
    std::optional<OutputFile> videoOut, csvOut;
    fs::path out, csvPath;
    bool mkv = false;
    if (!a.output.empty()) {
        out = a.output;
        mkv = isVideoOutput(out);
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
    if (!a.record.empty()) checkOutput(a.record, OutputOrigin::Named, rule, true);

    gl::ContextOptions copt;
    copt.width = width;
    copt.height = height;
    copt.title = "mirage live";
    gl::Context ctx = a.headless ? gl::Context::headless(copt) : gl::Context::window(copt);
    render::RendererOptions ropt;
    ropt.vplCount = a.vpls;
    ropt.exposure = a.exposure;
    render::Renderer renderer(scene, calib.intrinsics, ropt);
    FrameCompositor compositor(renderer, &tracker);

    std::unique_ptr<MatroskaWriter> video;
    if (mkv) video = std::make_unique<MatroskaWriter>(videoOut->temp(), cam.fps, a.jpegQuality);
    std::ofstream csv;
    const std::vector<std::string> passes = renderer.passNames();
    if (csvOut) {
        csv.open(csvOut->temp());
        if (!csv) throw FileError(csvPath.string(), "cannot create the timing CSV");
        csv << "frame,t,state,reason,camera_frame,dropped,driver_dropped,tracking_ms";
        for (const std::string& p : passes) csv << "," << p << "_ms";
        csv << ",gpu_ms,readback_ms,frame_ms,latency_ms,tx,ty,tz,qw,qx,qy,qz\n";
    }
    std::unique_ptr<LiveRecording> recording;
    if (!a.record.empty()) {
        LiveRecording::Options ro;
        ro.fps = cam.fps;
        ro.jpegQuality = a.jpegQuality;
        recording = std::make_unique<LiveRecording>(a.record, calibPath, boardPath, ro);
        spdlog::info("live: recording into {}", a.record);
    }

    spdlog::info("live: {} -> {} ({}x{}); tracking on {}", cam.description,
                 a.headless ? "headless" : "window", width, height, boardPath.string());
    installStopSignals();
    LatestFrameCapture capture(std::move(cam.source), cam.pacing);
    std::vector<double> latencies;
    int processed = 0;
    const auto tStart = Clock::now();
    bool windowClosed = false;
    bool reportedLost = false;
    while (!stopRequested() && !windowClosed && (a.maxFrames < 0 || processed < a.maxFrames)) {
        CapturedFrame f;
        if (!capture.next(f, 0.1)) {
            if (!a.headless) {
                ctx.pollEvents();
                windowClosed = ctx.shouldClose();
            }
            if (capture.ended()) break;
            // Unplugged: the window stays, the recording keeps every frame so far, and the
            // session goes on when the camera is back.
            const bool lost = capture.state() == LatestFrameCapture::State::Lost;
            if (lost && !reportedLost)
                spdlog::warn("live: camera lost: {}; waiting for it to come back",
                             capture.lostReason());
            if (!lost && reportedLost) spdlog::info("live: camera back");
            reportedLost = lost;
            continue;
        }
        if (reportedLost) spdlog::info("live: camera back");
        reportedLost = false;
        if (!f.bgr.empty() && (f.bgr.cols != width || f.bgr.rows != height))
            throw Error(fmt::format(
                "mirage live: {} delivers {}x{} frames but the calibration {} is for {}x{}; use "
                "the calibration of this camera at this size (or ask the camera for {}x{})",
                cam.description, f.bgr.cols, f.bgr.rows, calibPath.string(), width, height, width,
                height));
        const auto t0 = Clock::now();
        CompositedFrame cf = compositor.process(f.bgr, f.captureSeconds, f.problem, std::nullopt);
        if (f.bgr.empty()) spdlog::warn("live: {}", cf.pose.reason);
        if (!cf.image.empty()) {
            if (video) video->append(cf.image, f.captureSeconds);
            if (!out.empty() && !mkv)
                writeBgr8(out / cv::format("frame_%06d.png", processed), cf.image);
        }
        if (!a.headless) {
            if (cf.report) compositor.blitToWindow(width, height);
            ctx.swapBuffers();
            ctx.pollEvents();
            windowClosed = ctx.shouldClose();
        }
        // Shown (or written): the end of the capture-to-display latency.
        const double latencyMs = (steadySeconds() - f.captureSeconds) * 1e3;
        latencies.push_back(latencyMs);
        if (recording && !f.bgr.empty()) recording->append(f.bgr, f.captureSeconds, cf.pose);
        if (csv.is_open()) {
            csv << processed << "," << exactDecimal(f.captureSeconds) << ","
                << csvField(cf.pose.state) << "," << csvField(cf.pose.reason) << "," << f.sequence
                << "," << f.droppedBefore << "," << f.deviceDroppedBefore << "," << cf.trackingMs;
            for (const std::string& p : passes) {
                auto it = cf.passMs.find(p);
                csv << "," << (it == cf.passMs.end() ? 0.0 : it->second);
            }
            csv << "," << cf.gpuMs << "," << cf.readbackMs << "," << msSince(t0) << ","
                << latencyMs;
            if (cf.pose.pose) {
                const Pose& p = *cf.pose.pose;
                for (double v : {p.translation.x, p.translation.y, p.translation.z, p.rotation.w,
                                 p.rotation.x, p.rotation.y, p.rotation.z})
                    csv << "," << exactDecimal(v);
            } else {
                csv << ",,,,,,,";
            }
            csv << "\n";
            csv.flush();
        }
        ++processed;
    }
    const std::string captureError = capture.error();
    capture.stop();
    const double seconds = msSince(tStart) * 1e-3;
    if (video) video->close();
    if (csv.is_open()) closeChecked(csv, csvPath);
    if (videoOut) videoOut->commit();
    if (csvOut) csvOut->commit();
    if (recording) {
        recording->close();
        spdlog::info(
            "live: recorded {} frames into {} (replay: mirage replay {} --scene {} "
            "--poses {}/poses.csv -o OUT)",
            recording->frames(), a.record, a.record, a.scene, a.record);
    }
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
                    "/dev/videoN (or N) for a webcam; a session folder or a video stands in for "
                    "a camera, paced at its frame rate");
    cmd->add_option("--scene", args->scene,
                    "Scene (.gltf/.glb) with real proxies and virtual objects")
        ->required()
        ->check(CLI::ExistingFile);
    cmd->add_option("--calibration", args->calibration,
                    "The camera's calibration (OpenCV YAML from `mirage calibrate`; default: the "
                    "stand-in session's)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--board", args->board,
                    "Tag board file (default: the stand-in session's board)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--camera-fps", args->cameraFps,
                    "Frame rate asked of a webcam, or at which a stand-in delivers frames "
                    "(default: 30 / the stand-in's own)")
        ->check(finiteIn(0, 1000, true));
    cmd->add_option("--width", args->width, "Frame width asked of a webcam")
        ->capture_default_str()
        ->check(wholeIn(16, 16384));
    cmd->add_option("--height", args->height, "Frame height asked of a webcam")
        ->capture_default_str()
        ->check(wholeIn(16, 16384));
    cmd->add_flag("--headless", args->headless, "No window (EGL): for tests and benchmarks");
    cmd->add_option("--frames", args->maxFrames, "Stop after N processed frames")
        ->check(wholeIn(-1, 100000000));
    cmd->add_option("-o,--output", args->output,
                    "Write the composites: OUT.mkv (MJPEG video) or a folder of PNG frames, with "
                    "a per-frame CSV beside it");
    cmd->add_option("--record", args->record,
                    "Record the session (the camera's frames and the live poses) into this new "
                    "folder; replay it with `mirage replay`");
    cmd->add_option("--vpls", args->vpls, "Virtual point lights per frame")
        ->check(wholeIn(0, 16384));
    cmd->add_option("--exposure", args->exposure, "Rendered radiance -> camera linear units")
        ->check(finiteIn(0, 1e6, true));
    cmd->add_flag("--force", args->force, "Replace an existing CSV beside the output");
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
