#pragma once
// `mirage live` as a loop of stages (docs/live.md), each a member that can be built and tested
// alone:
//   capture  (LiveCapture)      the cameras' threads, newest frame, environment frame nearest
//   track    (PoseStage)        the pose decision of the frame (shared with replay)
//   render + composite (LiveRenderStage)  the renderer for the scene as placed, rebuilt on
//                               quality/effect/placement changes (FrameCompositor, as replay)
//   present  (LiveWindow)       the window with the HUD; absent headless
//   record   (LiveOutputs, LiveRecorder)  the composites and their CSV (-o); the session
//                               recorded for replay (--record, the HUD's record button)
// The session checks every input and output before any work, and on every way out (the frame
// limit, the end of a stand-in, SIGINT/SIGTERM, the window closed, an error) closes its outputs
// and recordings so that each is complete and playable, or is not left at all.
#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/PoseStage.h"
#include "app/live/LiveCapture.h"
#include "app/live/LiveInputs.h"
#include "app/live/LiveOptions.h"
#include "app/live/LiveOutputs.h"
#include "app/live/LiveRecorder.h"
#include "app/live/LiveRenderStage.h"
#include "app/live/LiveWindow.h"
#include "app/live/PlacementEditor.h"
#include "core/camera/CalibrationFile.h"
#include "core/gl/Context.h"
#include "core/scene/Scene.h"
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
    // One processed frame: track, render, composite, present (upload), write and record.
    void process(LiveFrame& frame);
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
    std::vector<std::string> passes_;

    // Loop state.
    LiveControls controls_;
    std::unique_ptr<PlacementEditor> placement_;
    CompositedFrame last_;  // the last processed frame (no image), for the HUD
    std::string viewProblem_, envProblem_;
    double envAgeMs_ = 0;
    std::vector<double> latencies_;
    int processed_ = 0;
    bool reportedLost_ = false, finished_ = false;
    double fpsEma_ = 0, lastLatencyMs_ = 0;
    std::chrono::steady_clock::time_point lastFrameAt_;
};

}  // namespace mirage::app
