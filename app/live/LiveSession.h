#pragma once
// `mirage live` as a loop of stages (docs/live.md), each a member that can be built and tested
// alone:
//   capture  (LiveCapture)      the cameras' threads, newest frame, environment frame nearest
//   track    (TrackingWorker + PoseStage)  the pose decision of the frame (shared with replay),
//                               on a thread of its own that tracks the next frame while the GL
//                               thread renders this one (PipelineSchedule times it); the pose
//                               rendered is predicted to the display time (PosePredictor)
//   render + composite (LiveRenderStage)  the renderer for the scene as placed, rebuilt on
//                               quality/effect/placement changes (FrameCompositor, as replay)
//   present  (LiveWindow)       the window with the HUD; absent headless
//   record   (LiveOutputs, LiveRecorder)  the composites and their CSV (-o); the session
//                               recorded for replay (--record, the HUD's record button)
// The session checks every input and output before any work, and on every way out (the frame
// limit, the end of a stand-in, SIGINT/SIGTERM, the window closed, an error) closes its outputs
// and recordings so that each is complete and playable, or is not left at all.
#include <atomic>
#include <chrono>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/PoseStage.h"
#include "app/live/DisplayPoseError.h"
#include "app/live/LiveCapture.h"
#include "app/live/LiveInputs.h"
#include "app/live/LiveOptions.h"
#include "app/live/LiveOutputs.h"
#include "app/live/LiveRecorder.h"
#include "app/live/LiveRenderStage.h"
#include "app/live/LiveWindow.h"
#include "app/live/PipelineSchedule.h"
#include "app/live/PlacementEditor.h"
#include "app/live/TrackingWorker.h"
#include "core/camera/CalibrationFile.h"
#include "core/gl/Context.h"
#include "core/scene/Scene.h"
#include "tracking/PosePredictor.h"
#include "tracking/Tracker.h"

namespace mirage::app {

class LiveSession {
public:
    // Opens the cameras, loads calibration, board and scene, checks the outputs, creates the GL
    // context and the stages. Throws mirage::Error (what is missing and what to do) before any
    // output is written.
    explicit LiveSession(const LiveOptions& options);
    ~LiveSession();
    LiveSession(const LiveSession&) = delete;
    LiveSession& operator=(const LiveSession&) = delete;

    // Runs until the frame limit, the end of the stand-in, SIGINT/SIGTERM or the window closes.
    // Returns the exit code: 0, or 128 + the signal that stopped it. Throws when the camera
    // failed (after closing the outputs).
    int run();

private:
    // The tracking worker's step (on its thread when pipelined): the next camera frame, its
    // pose decision and the camera's motion for the prediction.
    TrackingWorker::Result trackNext(TrackedLiveFrame& out, double timeoutSeconds);
    // One tracked frame, taken by the GL thread at `takenAt` (steady seconds): predict the pose
    // to the display time, render, composite, present (upload), write and record.
    void process(TrackedLiveFrame& frame, double takenAt);
    // The run's report: frames/s, drops, latency with and without prediction.
    void report(double seconds) const;
    // Takes the environment frame that came with `frame` into the renderer.
    void updateEnvironment(const LiveFrame& frame);
    // One window frame and what the user asked for in it. Returns false when the window closes.
    bool present();
    void finish();  // closes the outputs and the recording (also on the way out of an error)
    std::string environmentText() const;

    LiveOptions options_;
    CameraInput camera_;
    std::optional<EnvironmentInput> environment_;
    std::filesystem::path calibrationPath_, boardPath_, placementFile_;
    CameraCalibration calibration_;
    Scene scene_;
    std::unique_ptr<tracking::Tracker> tracker_;

    std::unique_ptr<LiveOutputs> outputs_;
    std::unique_ptr<gl::Context> context_;
    std::unique_ptr<LiveRenderStage> render_;
    std::unique_ptr<PoseStage> track_;
    std::unique_ptr<LiveRecorder> recorder_;
    std::unique_ptr<LiveWindow> window_;  // null headless
    std::unique_ptr<LiveCapture> capture_;
    std::unique_ptr<TrackingWorker> worker_;
    std::vector<std::string> passes_;

    // Tracking worker's thread only (the GL thread's while the worker is not threaded).
    tracking::PosePredictor predictor_;
    // Set by the GL thread when a new renderer starts its history again; the worker forgets
    // the held pose before its next frame.
    std::atomic<bool> restartTracking_{false};

    // Loop state.
    LiveControls controls_;
    std::unique_ptr<PlacementEditor> placement_;
    CompositedFrame last_;  // the last processed frame (no image), for the HUD
    std::string viewProblem_, envProblem_;
    double envAgeMs_ = 0;
    PipelineSchedule schedule_;
    bool requested_ = false;  // the worker was asked for the next frame
    // Per processed frame: capture-to-display latency, the prediction's horizon (0: not
    // predicted), the display time (steady seconds).
    std::vector<double> latencies_, predictMs_, displayedAt_;
    std::optional<DisplayPoseError> displayError_;  // a stand-in with ground truth
    double lastPredictMs_ = std::numeric_limits<double>::quiet_NaN();
    int processed_ = 0;
    bool reportedLost_ = false, finished_ = false;
    double fpsEma_ = 0, lastLatencyMs_ = 0;
    std::chrono::steady_clock::time_point lastFrameAt_;
    std::chrono::steady_clock::time_point runStart_;  // run()'s start (the --scan countdown)
};

}  // namespace mirage::app
