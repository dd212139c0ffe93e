#include "app/live/LiveSession.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>

#include "app/BoardPlane.h"
#include "app/EffectSwitches.h"
#include "app/InputChecks.h"
#include "app/KnobSettings.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/camera/CameraResponse.h"
#include "core/capture/CaptureFormat.h"
#include "core/scene/ScenePlacement.h"
#include "render/LightEstimation.h"

namespace mirage::app {

namespace fs = std::filesystem;

namespace {

// The webcam's exposure time for the motion blur: --shutter, else the locked --camera-exposure
// (V4L2 units of 100 us); otherwise the motion blur is off, and the log says so.
double liveShutterSeconds(const LiveOptions& a) {
    if (a.shutter) {
        spdlog::info("live: motion blur {} (--shutter {} s)", *a.shutter > 0 ? "on" : "off",
                     *a.shutter);
        return *a.shutter;
    }
    if (a.exposureLock.exposure) {
        const double s = double(*a.exposureLock.exposure) * 1e-4;
        spdlog::info("live: motion blur on (--camera-exposure: {} s)", s);
        return s;
    }
    spdlog::info(
        "live: motion blur off: no shutter time known; pass --shutter SECONDS (or lock the "
        "webcam's exposure with --camera-exposure)");
    return 0.0;
}

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    return v[v.size() / 2];
}

// The calibration and board of the session: as given, else found for the camera; what to do
// when there is none.
fs::path calibrationFor(const LiveOptions& a, const CameraInput& cam) {
    const fs::path p = !a.calibration.empty() ? fs::path(a.calibration) : cam.calibration;
    if (p.empty())
        throw Error("mirage live: no calibration for " + cam.description +
                    (cam.calibrationHint.empty() ? "" : ": " + cam.calibrationHint) +
                    "; or pass --calibration CAM.yaml (the file `mirage calibrate` saved for "
                    "this camera)");
    return p;
}
fs::path boardFor(const LiveOptions& a, const CameraInput& cam) {
    const fs::path p = !a.board.empty() ? fs::path(a.board) : cam.board;
    if (p.empty())
        throw Error("mirage live: no tag board for " + cam.description +
                    (cam.boardHint.empty() ? "" : ": " + cam.boardHint) +
                    "; or pass --board BOARD.json (the board file of the printed board, e.g. "
                    "from `mirage board`)");
    return p;
}

// Lights found in the environment camera's frames: as many as light estimation reports within
// the renderer's light budget.
int environmentLightCount(const LiveOptions& a, const Scene& scene) {
    if (!a.estimateLights) return 0;
    const int n = std::min(render::LightEstimationOptions{}.maxLights,
                           render::kMaxLights - int(scene.lightInstances().size()));
    if (n <= 0)
        throw Error(fmt::format(
            "mirage live --estimate-lights: scene {} already has {} lights, the real-time "
            "renderer's limit; remove one",
            a.scene, render::kMaxLights));
    return n;
}

}  // namespace

LiveSession::LiveSession(const LiveOptions& a) : options_(a) {
    if (a.scene.empty()) throw Error("mirage live: --scene SCENE is required");
    // From here on SIGINT/SIGTERM only ask the loop to stop: every output and recording opened
    // below is closed on the way out, never cut off by the default signal action.
    installStopSignals();
    camera_ = openCamera(a);
    calibrationPath_ = calibrationFor(a, camera_);
    boardPath_ = boardFor(a, camera_);
    spdlog::info("live: calibration {}, board {}", calibrationPath_.string(), boardPath_.string());
    calibration_ = loadCalibration(calibrationPath_);
    checkLooksLikeGltf(a.scene);
    scene_ = loadScene(a.scene);
    if (!scene_.hasVirtual())
        spdlog::warn("scene {} has no virtual object: the output will equal the footage", a.scene);
    const tracking::Board board = tracking::Board::load(boardPath_);
    tracking::TrackerOptions trackerOptions;
    trackerOptions.features.enabled = !a.boardOnly;
    tracker_ = std::make_unique<tracking::Tracker>(board, calibration_.intrinsics, trackerOptions);
    // Where the virtual objects stand: the saved placement (moves within the board's plane).
    placementFile_ = a.placement.empty() ? placementPath(a.scene) : fs::path(a.placement);
    const ScenePlacement placement = loadPlacement(placementFile_).value_or(ScenePlacement{});
    const PlacementPlane plane = boardPlane(board);
    if (!placement.isIdentity())
        spdlog::info(
            "live: placement from {}: moved {:.3f}, {:.3f} m, turned {:.1f} deg, scale {:.3f}",
            placementFile_.string(), placement.moveU, placement.moveV, placement.turnDeg,
            placement.scale);
    placement_ = std::make_unique<PlacementEditor>(placement);
    if (!a.envCamera.empty()) {
        environment_ = openEnvironmentCamera(a);
        spdlog::info("live: environment camera {} (calibration {})", environment_->description,
                     environment_->calibration.string());
    } else if (!a.envCalibration.empty()) {
        throw Error(
            "mirage live: --env-calibration without --env-camera; name the environment "
            "camera (a webcam, a video or a session) with --env-camera");
    } else if (a.estimateLights) {
        throw Error(
            "mirage live: --estimate-lights finds the lights in the environment camera's "
            "frames; name the environment camera with --env-camera");
    }
    LiveRenderSettings settings;
    settings.environmentLights = environmentLightCount(a, scene_);

    // Outputs, checked before any work (as replay's).
    OutputRule rule{camera_.inputs, a.force, "mirage live"};
    if (environment_)
        rule.inputs.insert(rule.inputs.end(), environment_->inputs.begin(),
                           environment_->inputs.end());
    rule.inputs.push_back(a.scene);
    rule.inputs.push_back(calibrationPath_);
    rule.inputs.push_back(boardPath_);
    outputs_ = std::make_unique<LiveOutputs>(a.output, rule);
    if (!a.record.empty()) {
        checkOutput(a.record, OutputOrigin::Named, rule, true);
        LiveRecording::checkFolder(a.record);
    }

    const int width = calibration_.intrinsics.width, height = calibration_.intrinsics.height;
    gl::ContextOptions copt;
    copt.width = width + kHudWidth;  // the view, and the HUD beside it
    copt.height = std::max(height, 560);
    copt.title = "mirage live";
    context_ = std::make_unique<gl::Context>(a.headless ? gl::Context::headless(copt)
                                                        : gl::Context::window(copt));
    settings.effects.exposureMatch.enabled = true;  // the camera's exposure changes on its own
    settings.effects.grain.noise.enabled = true;    // and it is a noisy, vignetting webcam
    settings.effects.grain.vignette.enabled = true;
    settings.effects.composite.cameraResponse = cameraResponseOrSrgb(calibrationPath_);
    switchEffectsOff(a.effectsOff, settings.effects);
    applyKnobSettings(a.knobSettings, settings.effects);
    settings.vpls = a.vpls;
    settings.budgetMs = a.budgetMs >= 0 ? a.budgetMs : 1000.0 / camera_.fps;
    settings.budgetTable = a.budgetTable;
    settings.exposure = a.exposure;
    settings.effects.motionBlur.shutterSeconds = liveShutterSeconds(a);
    settings.keepDirectLight = !a.headless;
    controls_.preset = settings.preset;
    controls_.effects = settings.effects;
    controls_.hideVirtual = a.hideVirtual;
    render_ =
        std::make_unique<LiveRenderStage>(scene_, plane, placement, calibration_.intrinsics,
                                          settings, environment_ ? &environment_->setup : nullptr);
    track_ = std::make_unique<PoseStage>(tracker_.get());
    passes_ = render_->passNames();
    outputs_->open(camera_.fps, a.jpegQuality, passes_);
    LiveRecording::Options ro;
    ro.fps = camera_.fps;
    ro.jpegQuality = a.jpegQuality;
    if (environment_) ro.environmentCalibration = environment_->calibration;
    recorder_ = std::make_unique<LiveRecorder>(a.record, calibrationPath_, boardPath_, ro, a.scene);
    if (!a.record.empty()) recorder_->start();
    spdlog::info("live: {} -> {} ({}x{}); tracking on {}", camera_.description,
                 a.headless ? "headless" : "window", width, height, boardPath_.string());
    if (!a.headless)
        window_ = std::make_unique<LiveWindow>(*context_, calibration_.intrinsics, plane);
    if (!camera_.groundTruth.empty())
        displayError_.emplace(camera_.groundTruth, camera_.releaseSeconds, calibration_.intrinsics);
}

LiveSession::~LiveSession() {
    // Left by an error: the recording is closed (every frame in it stays playable); the -o
    // outputs, not finished, leave nothing (their temporary files are removed).
    if (worker_) worker_->stop();  // first: its step reads the capture
    if (capture_) capture_->stop();
    try {
        if (recorder_) recorder_->stop();
    } catch (const Error& e) {
        spdlog::warn("live: {}", e.what());
    }
    restoreStopSignals();
}

int LiveSession::run() {
    capture_ = std::make_unique<LiveCapture>(camera_, environment_ ? &*environment_ : nullptr);
    worker_ = std::make_unique<TrackingWorker>(
        [this](TrackedLiveFrame& out, double timeout) { return trackNext(out, timeout); },
        !options_.noPipeline);
    spdlog::info(
        "live: {}; the pose rendered is {}",
        worker_->threaded()
            ? "pipelined (the next frame is tracked on its own thread while this one "
              "renders)"
            : "serial (each frame tracked, then rendered)",
        options_.noPredict ? "the tracked one (not predicted)" : "predicted to the display time");
    const auto tStart = runStart_ = Clock::now();
    lastFrameAt_ = Clock::now();
    auto timeLeft = [&] {
        return options_.maxSeconds <= 0 || msSince(tStart) < 1e3 * options_.maxSeconds;
    };
    while (!stopRequested() && (options_.maxFrames < 0 || processed_ < options_.maxFrames) &&
           timeLeft()) {
        TrackedLiveFrame f;
        bool got = false;
        double takenAt = 0;
        if (!controls_.paused) {
            if (!requested_) {
                // The first frame, or the first after a pause or a rebuild: a frame tracked
                // meanwhile is too old to show; the newest camera frame now.
                worker_->discard();
                worker_->request(steadySeconds());
                requested_ = true;
            }
            // The window redraws at most about every 15 ms while it waits for a frame (a frame
            // that arrives ends the wait at once), so the HUD stays responsive without spinning.
            const TrackingWorker::Result r = worker_->take(f, options_.headless ? 0.1 : 0.015);
            if (r == TrackingWorker::Result::Ended) break;
            got = r == TrackingWorker::Result::Frame;
            takenAt = steadySeconds();
            // The next frame, tracked while this one renders, ready when the GL thread is.
            const bool last = options_.maxFrames >= 0 && processed_ + 1 >= options_.maxFrames;
            if (got && !last) worker_->request(schedule_.nextTrackingStart(takenAt));
        } else {
            requested_ = false;
            std::this_thread::sleep_for(std::chrono::milliseconds(15));
        }
        const bool lost = capture_->lost();
        if (lost && !reportedLost_)
            spdlog::warn("live: camera lost: {}; waiting for it to come back",
                         capture_->lostReason());
        if (!lost && reportedLost_) spdlog::info("live: camera back");
        reportedLost_ = lost;
        if (got) process(f, takenAt);
        if (window_ && !present()) break;
        if (got) schedule_.addBusy(steadySeconds() - takenAt);
    }
    worker_->stop();
    const std::string captureError = capture_->stop();
    const double seconds = msSince(tStart) * 1e-3;
    finish();
    report(seconds);
    if (!captureError.empty()) throw Error("mirage live: " + captureError);
    return stopRequested() ? 128 + stopSignal() : 0;
}

void LiveSession::report(double seconds) const {
    const LatestFrameCapture& c = capture_->main();
    const int64_t stale = worker_->staleDropped();
    std::vector<double> intervals, behind;
    for (size_t k = 1; k < displayedAt_.size(); ++k)
        intervals.push_back((displayedAt_[k] - displayedAt_[k - 1]) * 1e3);
    for (size_t k = 0; k < latencies_.size(); ++k) behind.push_back(latencies_[k] - predictMs_[k]);
    const double latency = median(latencies_), interval = median(intervals);
    spdlog::info(
        "live: {} frames in {:.1f} s ({:.1f} frames/s, {}); camera delivered {}, dropped {} while "
        "processing was busy ({} of them tracked, then replaced by a newer frame before "
        "rendering; the driver dropped {}); camera reconnected {} times",
        processed_, seconds, processed_ / std::max(seconds, 1e-9),
        worker_->threaded() ? "pipelined" : "serial", c.delivered(), c.dropped() + stale, stale,
        c.deviceDropped(), c.reconnections());
    spdlog::info(
        "live: median capture-to-display latency {:.0f} ms, median frame interval {:.0f} ms "
        "(latency {:.2f}x the interval); without prediction the pose shown is {:.0f} ms old at "
        "display, with prediction (median {:.0f} ms ahead) {:.0f} ms{}",
        latency, interval, interval > 0 ? latency / interval : 0.0, latency, median(predictMs_),
        median(behind), options_.noPredict ? " (--no-predict: not used)" : "");
    if (displayError_ && displayError_->frames() > 0)
        spdlog::info("live: pose at display time against the stand-in's ground truth: {}",
                     displayError_->summary());
}

void LiveSession::finish() {
    if (finished_) return;
    finished_ = true;
    if (worker_) worker_->stop();
    if (capture_) capture_->stop();
    if (outputs_) outputs_->finish();
    if (recorder_) recorder_->stop();
}

void LiveSession::updateEnvironment(const LiveFrame& f) {
    if (!capture_->hasEnvironment()) return;
    if (f.newEnvironment) {
        const std::string problem = render_->updateEnvironment(f.envBgr, f.envSeconds);
        // Once per distinct problem: a wrong calibration fails every frame alike.
        if (!problem.empty() && problem != envProblem_) {
            envProblem_ = problem;
            spdlog::warn("live: environment frames not used: {}", envProblem_);
        }
    }
    envAgeMs_ = render_->hasEnvironmentFrame()
                    ? (f.main.captureSeconds - render_->environmentSeconds()) * 1e3
                    : std::numeric_limits<double>::quiet_NaN();
}

TrackingWorker::Result LiveSession::trackNext(TrackedLiveFrame& out, double timeoutSeconds) {
    if (restartTracking_.exchange(false)) {
        track_->restart();
        predictor_.reset();
    }
    if (!capture_->next(out.frame, timeoutSeconds))
        return capture_->ended() ? TrackingWorker::Result::Ended : TrackingWorker::Result::Timeout;
    const CapturedFrame& f = out.frame.main;
    const int width = calibration_.intrinsics.width, height = calibration_.intrinsics.height;
    if (!f.bgr.empty() && (f.bgr.cols != width || f.bgr.rows != height))
        throw Error(fmt::format(
            "mirage live: {} delivers {}x{} frames but the calibration {} is for {}x{}; use "
            "the calibration of this camera at this size (or ask the camera for {}x{})",
            camera_.description, f.bgr.cols, f.bgr.rows, calibrationPath_.string(), width, height,
            width, height));
    const auto t0 = Clock::now();
    out.pose = track_->decide(f.bgr, f.captureSeconds, f.problem, std::nullopt);
    out.trackingMs = msSince(t0);
    out.trackingMode = track_->lastMode();
    // The motion for the prediction: from tracked poses only (a held pose is already old and
    // is shown as it is; a lost frame ends the motion).
    if (out.pose.state == "ok" && out.pose.pose) {
        predictor_.update(*out.pose.pose, f.captureSeconds);
        out.motion = predictor_;
    } else if (!out.pose.pose) {
        predictor_.reset();
    }
    out.trackedSeconds = steadySeconds();
    return TrackingWorker::Result::Frame;
}

void LiveSession::process(TrackedLiveFrame& tracked, double takenAt) {
    LiveFrame& frame = tracked.frame;
    const CapturedFrame& f = frame.main;
    envAgeMs_ = std::numeric_limits<double>::quiet_NaN();
    updateEnvironment(frame);
    const auto t0 = Clock::now();
    schedule_.addTracking(tracked.trackingMs * 1e-3);
    // The pose at the time the frame is expected on display, not at its capture.
    PoseRow shown = tracked.pose;
    double predictMs = std::numeric_limits<double>::quiet_NaN();
    if (!options_.noPredict && tracked.motion && tracked.motion->velocity() && shown.pose) {
        const double displayAt = schedule_.expectedDisplay(takenAt);
        predictMs = tracked.motion->horizon(displayAt) * 1e3;
        shown.pose = tracked.motion->predict(displayAt);
    }
    CompositedFrame cf =
        render_->composite(f.bgr, std::move(shown), !controls_.hideVirtual, f.captureSeconds);
    cf.trackingMs = tracked.trackingMs;
    cf.trackingMode = tracked.trackingMode;
    if (f.bgr.empty()) spdlog::warn("live: {}", cf.pose.reason);
    if (!cf.image.empty()) {
        outputs_->writeImage(processed_, cf.image, f.captureSeconds);
        if (window_) {
            viewProblem_.clear();
            cv::Mat img = cf.image;
            if (kBufferViews[controls_.view].resource && cf.report) {
                try {
                    img = render_->view(controls_.view);
                } catch (const Error& e) {
                    viewProblem_ = e.what();
                }
            }
            window_->show(img);
        }
    }
    // Written (headless) or uploaded for display: the end of the capture-to-display latency
    // (the window's swap follows).
    const double displayedAt = steadySeconds();
    const double latencyMs = (displayedAt - f.captureSeconds) * 1e3;
    schedule_.addDisplayDelay(displayedAt - takenAt);
    latencies_.push_back(latencyMs);
    predictMs_.push_back(std::isfinite(predictMs) ? predictMs : 0.0);
    displayedAt_.push_back(displayedAt);
    lastLatencyMs_ = latencyMs;
    lastPredictMs_ = predictMs;
    if (displayError_ && cf.pose.pose && tracked.pose.pose)
        displayError_->add(f.sequence, f.captureSeconds, displayedAt, *cf.pose.pose,
                           *tracked.pose.pose);
    recorder_->append(f.bgr, f.captureSeconds, cf.pose, frame.envBgr, frame.envSeconds);
    // The GL thread's time for the frame: tracking too when it ran here (serial).
    const double frameMs = msSince(t0) + (worker_->threaded() ? 0.0 : tracked.trackingMs);
    LivePipelineTimes times;
    times.handoffMs =
        worker_->threaded() ? std::max(0.0, takenAt - tracked.trackedSeconds) * 1e3 : 0;
    times.predictMs = predictMs;
    outputs_->writeRow(processed_, f, envAgeMs_, cf, frameMs, latencyMs, times);
    const double dt = msSince(lastFrameAt_) * 1e-3;
    lastFrameAt_ = Clock::now();
    if (processed_ > 0 && dt > 0) fpsEma_ = fpsEma_ == 0 ? 1 / dt : 0.8 * fpsEma_ + 0.2 / dt;
    last_ = std::move(cf);
    last_.image.release();
    ++processed_;
}

std::string LiveSession::environmentText() const {
    if (!environment_) return "";
    return environment_->description +
           (!render_->hasEnvironmentFrame() ? ", waiting for a frame"
            : capture_->environmentEnded()  ? ", ended (its last frame lights)"
            : std::isfinite(envAgeMs_)      ? cv::format(", frame %.0f ms older", envAgeMs_)
                                            : "");
}

bool LiveSession::present() {
    HudStatus s;
    if (capture_->lost()) s.lostReason = capture_->lostReason();
    s.fps = fpsEma_;
    s.latencyMs = lastLatencyMs_;
    s.predictMs = lastPredictMs_;
    s.pipelined = worker_->threaded();
    s.dropped = static_cast<long long>(capture_->main().dropped());
    s.driverDropped = static_cast<long long>(capture_->main().deviceDropped());
    s.last = &last_;
    s.exposureText = camera_.exposureText;
    s.exposureWarnings = camera_.exposureWarnings;
    s.environmentText = environmentText();
    if (const render::FrameBudgetGovernor* g = render_->governor()) s.budgetText = g->summary();
    s.viewProblem = viewProblem_;
    if (recorder_->recording())
        s.recordingText =
            cv::format("REC %s: %d frames", recorder_->dir().string().c_str(), recorder_->frames());
    if (options_.maxSeconds > 0)  // the scan of --scan: how long it still records
        s.scanText = cv::format("SCAN, %.0f s left: walk around the table",
                                std::max(0.0, options_.maxSeconds - msSince(runStart_) * 1e-3));
    s.placement = placement_->placement();
    s.placementPending = placement_->pending();
    const HudRequests req = window_->draw(s, controls_);
    if (req.placement) {
        // The objects follow in the next frame: moved in place (shadows, indirect light,
        // caustics and impostors redone in that frame), or, for a translucent object whose voxel
        // number map lies in the world, by a new renderer once the keys rest.
        const bool inPlace = render_->move(*req.placement);
        placement_->change(*req.placement, inPlace, Clock::now());
    }
    bool closed = req.close;
    if (!options_.screenshot.empty() && processed_ >= options_.screenshotAfter) {
        window_->savePng(options_.screenshot);
        closed = true;
    }
    if (req.screenshot) window_->savePng(timestampName("mirage-live-", ".png"));
    window_->swap();
    if (req.toggleRecord) {
        try {
            if (recorder_->recording())
                recorder_->stop();
            else
                recorder_->start();
        } catch (const Error& e) {
            // A recording that cannot start (a folder in the way, a full disk) must not end the
            // session: say why and go on.
            spdlog::warn("live: {}", e.what());
        }
    }
    LiveRenderSettings& settings = render_->settings();
    bool rebuild = false;
    if (placement_->settle(Clock::now(), window_->dragging())) {
        rebuild = placement_->rebuildNeeded();
        try {
            savePlacement(placementFile_, placement_->placement());
            spdlog::info("live: placement saved to {}", placementFile_.string());
        } catch (const Error& e) {
            spdlog::warn("live: placement not saved: {}", e.what());
        }
    }
    if (req.rebuild) {
        // A new renderer with the preset's options and the effects as switched; the temporal
        // history starts again.
        if (controls_.preset != settings.preset) {
            settings.preset = controls_.preset;
            settings.vpls = kQualityPresets[settings.preset].vpls;
            spdlog::info("live: quality {}", kQualityPresets[settings.preset].name);
        }
        settings.effects = controls_.effects;
        rebuild = true;
    }
    if (rebuild) {
        render_->rebuild();
        // On the worker's thread before its next frame; the frame it tracked during the
        // rebuild is too old to show: the next is asked for now.
        restartTracking_ = true;
        requested_ = false;
        last_.report = nullptr;
    }
    return !closed;
}

}  // namespace mirage::app
