#pragma once
// One capture thread per camera with a latest-frame hand-off (docs/live.md): the thread reads
// frames from a FrameSource as fast as the camera delivers them and keeps only the newest in a
// one-frame slot; the consumer (the live loop's GL thread) takes the newest frame when it is
// ready for one. A frame replaced in the slot before anyone took it is dropped and counted, so
// a consumer slower than the camera sees the newest footage with a bounded delay instead of a
// queue that grows without end.
//
// A real camera (V4l2Camera) paces itself: read() blocks until the driver has the next frame.
// A recorded video or session standing in for a camera is paced here at its frame rate
// (Options::paceFps or the source's own timestamps), so that it drops frames exactly as a camera
// would when processing is slower.
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <opencv2/core.hpp>

#include "core/session/FrameSource.h"

namespace mirage {

struct CapturedFrame {
    cv::Mat bgr;            // 8-bit BGR, sRGB-encoded; empty = lost (problem says why)
    std::string problem;    // FrameSource::lastProblem() of the frame
    int64_t sequence = -1;  // the camera's frame counter (0-based position in the source)
    // Capture time, seconds on CLOCK_MONOTONIC (std::chrono::steady_clock): the driver's
    // timestamp for a V4L2 camera, the moment the frame was released for a paced stand-in.
    // Latency = display time - captureSeconds.
    double captureSeconds = 0;
    // Frames the hand-off dropped before this one was taken (replaced in the slot unseen).
    int64_t droppedBefore = 0;
    int64_t deviceDroppedBefore = 0;  // and those the device dropped (driver sequence gaps)
};

class LatestFrameCapture {
public:
    struct Options {
        // `paceBySourceTime`: release each frame at the source's own timestamp (relative to its
        // first), as it was recorded; frames without one (and every frame without that flag)
        // at start + i / paceFps when paceFps > 0 (a stand-in for a camera at that rate); else
        // no pacing (the source blocks by itself, as a camera does).
        double paceFps = 0;
        bool paceBySourceTime = false;
        // Capture time from the source's lastTimestamp() (a V4L2 camera's driver clock, which
        // is CLOCK_MONOTONIC) instead of the steady clock when the frame is released.
        bool sourceClockIsMonotonic = false;
        // A camera that fails (unplugged: ENODEV, a stalled stream) is reopened with this,
        // every `retrySeconds`, until it is back or stop(); meanwhile state() is Lost with the
        // reason. Unset: a failure ends the stream (error()).
        std::function<std::unique_ptr<FrameSource>()> reopen;
        double retrySeconds = 0.5;
    };
    enum class State { Streaming, Lost, Ended };
    // Starts the capture thread. The source is read only by that thread from now on.
    LatestFrameCapture(std::unique_ptr<FrameSource> source, Options options);
    ~LatestFrameCapture();  // stops and joins the thread
    LatestFrameCapture(const LatestFrameCapture&) = delete;
    LatestFrameCapture& operator=(const LatestFrameCapture&) = delete;

    // Waits up to timeoutSeconds for a frame newer than the last one taken and moves it out of
    // the slot. Returns false on timeout or once the source has ended (or failed: error()) and
    // its last frame was taken.
    bool next(CapturedFrame& frame, double timeoutSeconds);
    bool ended() const;         // the source ended or failed and the slot is empty
    std::string error() const;  // the source's exception text, if it failed
    int64_t delivered() const;  // frames the source delivered (taken + dropped + waiting)
    int64_t dropped() const;    // frames replaced in the slot before they were taken
    // Frames the device dropped (driver sequence gaps), over every reconnection.
    int64_t deviceDropped() const;
    State state() const;
    std::string lostReason() const;  // why the camera is (or last was) lost
    int reconnections() const;
    void stop();  // ends the thread (also done by the destructor)

private:
    void run();
    bool reconnect(const std::string& reason);  // false when stopped meanwhile

    std::unique_ptr<FrameSource> source_;
    Options options_;
    mutable std::mutex mutex_;
    std::condition_variable ready_, wake_;
    std::optional<CapturedFrame> slot_;
    bool stop_ = false, ended_ = false;
    std::string error_;
    int64_t delivered_ = 0, dropped_ = 0, deviceDroppedBase_ = 0, deviceDropped_ = 0;
    bool lost_ = false;
    std::string lostReason_;
    int reconnections_ = 0;
    std::thread thread_;
};

}  // namespace mirage
