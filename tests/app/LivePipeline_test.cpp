// The pipelined live loop's stages, each alone (app/live/TrackingWorker.h,
// app/live/PipelineSchedule.h, app/live/DisplayPoseError.h): the tracking worker with a fake
// step standing in for capture + tracking, the schedule's arithmetic, and the pose error at
// display time against a ground truth.
#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include <gtest/gtest.h>

#include "app/live/DisplayPoseError.h"
#include "app/live/PipelineSchedule.h"
#include "app/live/TrackingWorker.h"
#include "core/Error.h"
#include "core/capture/CaptureFormat.h"

namespace mirage::test {
namespace {

using app::TrackedLiveFrame;
using app::TrackingWorker;
using Result = TrackingWorker::Result;

// A camera whose frames are numbered 0, 1, 2, ...: each step "tracks" the next one in
// `trackMs`, remembers when it started, and ends the stream after `frames` (or throws at
// `throwAt`).
struct FakeCamera {
    std::atomic<int> next{0};
    std::atomic<int> steps{0};
    int frames = 1000;
    int throwAt = -1;
    double trackMs = 2;
    std::atomic<double> lastStart{0};

    TrackingWorker::Step step() {
        return [this](TrackedLiveFrame& out, double) {
            lastStart = steadySeconds();
            const int k = next++;
            if (k == throwAt) throw Error("the camera's driver failed");
            if (k >= frames) return Result::Ended;
            std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(trackMs));
            out.frame.main.sequence = k;
            out.frame.main.captureSeconds = steadySeconds();
            out.pose.state = "ok";
            out.trackedSeconds = steadySeconds();
            ++steps;
            return Result::Frame;
        };
    }
};

// Waits (up to 5 s) until `done` holds.
template <class F>
bool waitFor(F done) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (!done()) {
        if (std::chrono::steady_clock::now() > until) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return true;
}

// One request, one frame: every frame taken is newer than the one before, none dropped.
TEST(TrackingWorker, DeliversTrackedFramesInOrder) {
    FakeCamera cam;
    TrackingWorker worker(cam.step(), true);
    ASSERT_TRUE(worker.threaded());
    int64_t last = -1;
    for (int i = 0; i < 20; ++i) {
        worker.request(steadySeconds());
        TrackedLiveFrame f;
        ASSERT_EQ(worker.take(f, 5.0), Result::Frame) << "frame " << i;
        EXPECT_GT(f.frame.main.sequence, last);
        EXPECT_EQ(f.frame.main.droppedBefore, 0);
        EXPECT_EQ(f.pose.state, "ok");
        last = f.frame.main.sequence;
    }
    EXPECT_EQ(worker.staleDropped(), 0);
    // Without a request the worker does not track: nothing to take.
    TrackedLiveFrame f;
    EXPECT_EQ(worker.take(f, 0.05), Result::Timeout);
}

// A tracked frame not taken before a newer one is tracked is dropped and counted: the frame
// taken is the newest, and its droppedBefore counts the stale one. discard() drops too.
TEST(TrackingWorker, DropsStaleFramesAndCountsThem) {
    FakeCamera cam;
    TrackingWorker worker(cam.step(), true);
    worker.request(steadySeconds());
    ASSERT_TRUE(waitFor([&] { return cam.steps == 1; }));
    worker.request(steadySeconds());
    ASSERT_TRUE(waitFor([&] { return cam.steps == 2; }));
    ASSERT_TRUE(waitFor([&] { return worker.staleDropped() == 1; }));
    TrackedLiveFrame f;
    ASSERT_EQ(worker.take(f, 1.0), Result::Frame);
    EXPECT_EQ(f.frame.main.sequence, 1);
    EXPECT_EQ(f.frame.main.droppedBefore, 1);
    worker.request(steadySeconds());
    ASSERT_TRUE(waitFor([&] { return cam.steps == 3; }));
    // The step counts before the slot is filled: wait for the hand-off, then drop it.
    ASSERT_TRUE(waitFor([&] {
        worker.discard();
        return worker.staleDropped() == 2;
    }));
    EXPECT_EQ(worker.take(f, 0.05), Result::Timeout) << "a discarded frame was taken";
    worker.request(steadySeconds());
    ASSERT_EQ(worker.take(f, 1.0), Result::Frame);
    EXPECT_EQ(f.frame.main.sequence, 3);
    EXPECT_EQ(f.frame.main.droppedBefore, 2);
}

// The worker starts on a request no earlier than asked (the pipelined loop asks for the moment
// the GL thread will be ready, less the tracking time), and a newer request moves the start.
TEST(TrackingWorker, StartsTrackingNoEarlierThanAsked) {
    FakeCamera cam;
    TrackingWorker worker(cam.step(), true);
    const double asked = steadySeconds() + 0.3;
    worker.request(asked + 10.0);  // replaced at once by the nearer request below
    worker.request(asked);
    TrackedLiveFrame f;
    ASSERT_EQ(worker.take(f, 5.0), Result::Frame);
    EXPECT_GE(cam.lastStart.load(), asked);
    EXPECT_EQ(cam.steps, 1);
}

// The end of the stream ends the worker: the frames tracked before it are taken, then Ended,
// every time; the thread is joined.
TEST(TrackingWorker, EndsCleanlyAtTheEndOfTheStream) {
    FakeCamera cam;
    cam.frames = 3;
    TrackingWorker worker(cam.step(), true);
    int taken = 0;
    for (int i = 0; i < 10; ++i) {
        worker.request(steadySeconds());
        TrackedLiveFrame f;
        const Result r = worker.take(f, 5.0);
        if (r == Result::Ended) break;
        ASSERT_EQ(r, Result::Frame);
        ++taken;
    }
    EXPECT_EQ(taken, 3);
    TrackedLiveFrame f;
    EXPECT_EQ(worker.take(f, 0.0), Result::Ended);
    worker.stop();
    worker.stop();  // twice is fine
}

// An exception in the step (a camera that fails, a frame of the wrong size) ends the worker
// and reaches the GL thread from take(), after the frames tracked before it.
TEST(TrackingWorker, PassesTheStepsErrorToTake) {
    FakeCamera cam;
    cam.throwAt = 1;
    TrackingWorker worker(cam.step(), true);
    worker.request(steadySeconds());
    TrackedLiveFrame f;
    ASSERT_EQ(worker.take(f, 5.0), Result::Frame);
    worker.request(steadySeconds());
    try {
        worker.take(f, 5.0);
        ADD_FAILURE() << "the step's error did not reach take()";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("driver failed"), std::string::npos) << e.what();
    }
}

// stop() (and the destructor) ends a worker that waits for a request, for its start time or
// inside a step that waits for a camera frame that never comes.
TEST(TrackingWorker, StopsWhileWaiting) {
    {
        FakeCamera cam;
        TrackingWorker idle(cam.step(), true);
    }
    {
        FakeCamera cam;
        TrackingWorker later(cam.step(), true);
        later.request(steadySeconds() + 3600);
    }
    std::atomic<int> calls{0};
    TrackingWorker starved(
        [&](TrackedLiveFrame&, double timeout) {
            ++calls;
            std::this_thread::sleep_for(std::chrono::duration<double>(timeout));
            return Result::Timeout;
        },
        true);
    starved.request(steadySeconds());
    ASSERT_TRUE(waitFor([&] { return calls >= 2; })) << "a timed-out step was not tried again";
    starved.stop();
    TrackedLiveFrame f;
    EXPECT_EQ(starved.take(f, 0.0), Result::Ended);
}

// Not threaded (--no-pipeline): take() runs the step on the caller's thread.
TEST(TrackingWorker, NotThreadedTakeTracksOnTheCallersThread) {
    std::thread::id stepThread;
    int k = 0;
    TrackingWorker worker(
        [&](TrackedLiveFrame& out, double) {
            stepThread = std::this_thread::get_id();
            if (k == 2) return Result::Ended;
            out.frame.main.sequence = k++;
            return Result::Frame;
        },
        false);
    EXPECT_FALSE(worker.threaded());
    TrackedLiveFrame f;
    ASSERT_EQ(worker.take(f, 0.1), Result::Frame);
    EXPECT_EQ(stepThread, std::this_thread::get_id());
    ASSERT_EQ(worker.take(f, 0.1), Result::Frame);
    EXPECT_EQ(f.frame.main.sequence, 1);
    EXPECT_EQ(worker.take(f, 0.1), Result::Ended);
    EXPECT_EQ(worker.take(f, 0.1), Result::Ended);
}

// The schedule starts tracking so that it ends when the GL thread is ready, with a lead; the
// medians ignore one slow frame; without measurements it starts at once.
TEST(PipelineSchedule, StartsTrackingToBeReadyWhenTheRenderIs) {
    app::PipelineSchedule s;
    EXPECT_DOUBLE_EQ(s.nextTrackingStart(100.0), 100.0);
    EXPECT_DOUBLE_EQ(s.expectedDisplay(100.0), 100.0);
    for (int i = 0; i < 5; ++i) {
        s.addBusy(0.300);
        s.addTracking(0.040);
        s.addDisplayDelay(0.280);
    }
    s.addBusy(2.0);  // a rebuild
    const double lead =
        0.040 * (1 + app::PipelineSchedule::kLeadFraction) + app::PipelineSchedule::kLeadSeconds;
    EXPECT_NEAR(s.nextTrackingStart(100.0), 100.0 + 0.300 - lead, 1e-12);
    EXPECT_NEAR(s.expectedDisplay(100.0), 100.28, 1e-12);
    // Tracking slower than the render: at once (the GL thread waits for the worker).
    for (int i = 0; i < 9; ++i) s.addTracking(0.5);
    EXPECT_DOUBLE_EQ(s.nextTrackingStart(100.0), 100.0);
    s.addBusy(std::nan(""));  // ignored
    EXPECT_DOUBLE_EQ(s.busySeconds(), 0.300);
}

// A camera orbiting a point 0.15 m beside the world origin at 2 rad/s, looking at that point:
// the origin's image moves.
Pose orbitPose(double t) {
    const double a = 2.0 * t;
    const glm::dvec3 centre(0.15, 0, 0);
    return cameraLookingAt(centre + glm::dvec3(0.5 * std::cos(a), 0.3, 0.5 * std::sin(a)), centre,
                           {0, 1, 0});
}

CameraIntrinsics camera640() {
    CameraIntrinsics c;
    c.width = 640;
    c.height = 480;
    c.fx = c.fy = 600;
    c.cx = 320;
    c.cy = 240;
    return c;
}

// Against a ground truth orbiting at a constant rate: the pose predicted to the display time
// is right there, the tracked pose is off by the motion during the latency; past the
// stand-in's last frame (or without ground truth) nothing is counted; a looped stand-in's
// counter wraps to its frames.
TEST(DisplayPoseError, JudgesEachFrameAtItsDisplayTime) {
    const double fps = 30;
    std::vector<std::optional<Pose>> truth;
    std::vector<double> release;
    for (int i = 0; i < 10; ++i) {
        truth.push_back(orbitPose(i / fps));
        release.push_back(i / fps);
    }
    truth[7].reset();
    app::DisplayPoseError e(truth, release, camera640());
    // Between frames the ground truth moves on with constant velocity: exact for an orbit.
    const auto mid = e.groundTruthAt(2.5 / fps);
    ASSERT_TRUE(mid);
    EXPECT_LT(glm::length(mid->translation - orbitPose(2.5 / fps).translation), 1e-12);
    // Frame 2 captured at steady time 50 s, displayed 0.1 s later.
    const Pose tracked = orbitPose(2 / fps), predicted = orbitPose(2 / fps + 0.1);
    const auto s = e.add(2, 50.0, 50.1, predicted, tracked);
    ASSERT_TRUE(s);
    EXPECT_LT(s->shownPx, 1e-6);
    EXPECT_LT(s->shownMm, 1e-6);
    EXPECT_GT(s->trackedPx, 10.0);  // 0.2 rad of orbit
    EXPECT_GT(s->trackedMm, 90.0);
    // Frame 12 of a looped stand-in is frame 2 again.
    EXPECT_TRUE(e.add(12, 80.0, 80.1, predicted, tracked));
    // Displayed past the last frame, or between frames without ground truth: not judged.
    EXPECT_FALSE(e.add(8, 60.0, 60.1, predicted, tracked));
    EXPECT_FALSE(e.add(6, 60.0, 60.04, predicted, tracked));
    EXPECT_EQ(e.frames(), 2);
    EXPECT_NE(e.summary().find("without prediction"), std::string::npos) << e.summary();
}

}  // namespace
}  // namespace mirage::test
