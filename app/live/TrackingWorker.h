#pragma once
// The tracking stage of the pipelined live loop (docs/live.md, "How it runs"): a thread of its
// own takes the newest camera frame and tracks it while the GL thread renders the frame before,
// and hands the tracked frame over in a one-frame slot (a bounded queue of one: a tracked frame
// not taken before a newer one is ready is dropped as stale and counted). The GL context never
// leaves the GL thread; only frames, poses and their motion cross.
//
// The GL thread asks for each frame with request(start): the worker waits until `start` (the
// moment the GL thread expects to be ready for the frame, less the time tracking takes) and
// then tracks the newest camera frame, so the frame it hands over is as fresh as the render
// loop allows instead of waiting in the slot while the frame before renders. Not threaded
// (--no-pipeline), take() tracks the next frame itself on the caller's thread: the serial loop.
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "app/live/LiveCapture.h"
#include "core/session/PosesCsv.h"
#include "tracking/PosePredictor.h"

namespace mirage::app {

// One camera frame as tracked for the render stage.
struct TrackedLiveFrame {
    LiveFrame frame;
    PoseRow pose;  // the decided pose (app/PoseStage.h), T_world_camera
    // The camera's motion up to this frame's pose (its last pose): set when the pose was
    // tracked ok in this frame, for the prediction to the display time; unset for a held, a
    // lost or a missing pose (those are shown as they are).
    std::optional<tracking::PosePredictor> motion;
    std::string trackingMode;   // PoseStage::lastMode()
    double trackingMs = 0;      // wall time of the pose decision, ms
    double trackedSeconds = 0;  // when tracking finished (steady clock, seconds)
};

class TrackingWorker {
public:
    enum class Result { Frame, Timeout, Ended };
    // Tracks the next camera frame into `out`, waiting up to `timeoutSeconds` for one: Frame,
    // Timeout (no frame came), or Ended (the stream is over). Called only by the worker's
    // thread (by take()'s caller when not threaded). An exception ends the worker; take()
    // throws it again.
    using Step = std::function<Result(TrackedLiveFrame& out, double timeoutSeconds)>;

    // `threaded` false: no thread; take() runs the step itself.
    TrackingWorker(Step step, bool threaded);
    ~TrackingWorker();  // stop()
    TrackingWorker(const TrackingWorker&) = delete;
    TrackingWorker& operator=(const TrackingWorker&) = delete;

    // Asks for the next frame: tracking starts at `startSeconds` (steady clock) on the newest
    // camera frame then (at once when that has passed). A request made while one is pending
    // replaces it. Not threaded: nothing to do.
    void request(double startSeconds);
    // Waits up to `timeoutSeconds` for a tracked frame and moves it out of the slot; its
    // `droppedBefore` counts the stale frames too. Ended once the stream is over and the slot
    // is empty; throws the step's exception when it failed.
    Result take(TrackedLiveFrame& out, double timeoutSeconds);
    // Drops the frame waiting in the slot, if any (counted stale): after a pause or a long
    // rebuild it is too old to show.
    void discard();
    // Tracked frames dropped unseen (replaced in the slot, or discarded).
    int64_t staleDropped() const;
    bool threaded() const { return threaded_; }
    // Ends the thread (after the step in progress, which waits at most its timeout).
    void stop();

    // How long the worker's step waits for a camera frame before it looks at stop() again.
    static constexpr double kStepTimeoutSeconds = 0.1;

private:
    void run();

    Step step_;
    bool threaded_;
    mutable std::mutex mutex_;
    std::condition_variable wake_, ready_;  // wake_: the worker; ready_: take()
    std::optional<TrackedLiveFrame> slot_;
    std::optional<double> requestStart_;  // a pending request (steady seconds)
    uint64_t requestId_ = 0;
    bool stop_ = false, ended_ = false;
    std::exception_ptr error_;
    int64_t stale_ = 0;
    std::thread thread_;
};

}  // namespace mirage::app
