#include "app/live/LiveInputs.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <functional>

#include "core/Error.h"
#include "core/Log.h"
#include "core/camera/CalibrationFile.h"
#include "core/camera/Radiometry.h"
#include "core/capture/CameraCatalog.h"
#include "core/capture/CaptureFormat.h"
#include "core/capture/V4l2Camera.h"
#include "core/capture/V4l2Device.h"
#include "core/session/Session.h"

namespace mirage::app {
namespace {

namespace fs = std::filesystem;

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

}  // namespace

std::string timestampName(const char* prefix, const char* ext) {
    const std::time_t now = std::time(nullptr);
    char buf[64];
    std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", std::localtime(&now));
    return std::string(prefix) + buf + ext;
}

namespace {

// When a session stand-in releases each frame (CameraInput::releaseSeconds): its own times
// relative to its first, or i / fps when paced at a rate (or when a time is missing). No ground
// truth at all: none.
void releaseTimes(CameraInput& in) {
    if (std::none_of(in.groundTruth.begin(), in.groundTruth.end(),
                     [](const std::optional<Pose>& p) { return p.has_value(); })) {
        in.groundTruth.clear();
        in.releaseSeconds.clear();
        return;
    }
    const bool own = in.pacing.paceBySourceTime &&
                     std::all_of(in.releaseSeconds.begin(), in.releaseSeconds.end(),
                                 [](double t) { return std::isfinite(t); });
    const double t0 = in.releaseSeconds.empty() ? 0.0 : in.releaseSeconds.front();
    for (size_t i = 0; i < in.releaseSeconds.size(); ++i)
        in.releaseSeconds[i] = own ? in.releaseSeconds[i] - t0 : double(i) / in.fps;
}

}  // namespace

CameraInput openCamera(const LiveOptions& a) {
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
        const size_t column = size_t(main - s.cameras.data());
        for (const FrameRecord& r : s.frames) {
            in.groundTruth.push_back(r.groundTruth);
            in.releaseSeconds.push_back(column < r.timestamps.size() ? r.timestamps[column]
                                                                     : std::nan(""));
        }
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
    releaseTimes(in);
    return in;
}

EnvironmentInput openEnvironmentCamera(const LiveOptions& a) {
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

}  // namespace mirage::app
