#pragma once
// The capture stage of a live session (docs/live.md): one capture thread per camera with a
// latest-frame hand-off (core/capture/LatestFrameCapture.h), and for each main frame the
// environment frame nearest to it in time. Capture never waits for processing: frames that
// arrive while the loop is busy replace each other in the slot and are counted as dropped.
#include <atomic>
#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "app/live/LiveInputs.h"
#include "core/capture/LatestFrameCapture.h"

namespace mirage::app {

// One main frame as taken by the loop, with the environment camera's newest frame.
struct LiveFrame {
    CapturedFrame main;
    // A new environment frame came with this main frame (the one nearest in time that the
    // hand-off had): envBgr and envSeconds hold it. Otherwise they hold the last one delivered
    // (empty before the first).
    bool newEnvironment = false;
    cv::Mat envBgr;
    double envSeconds = 0;  // capture time, seconds on CLOCK_MONOTONIC
};

class LiveCapture {
public:
    // Starts the capture threads; the sources are read only by them from now on. `env` may be
    // null (no environment camera).
    LiveCapture(CameraInput& camera, EnvironmentInput* env);

    // Waits up to `timeoutSeconds` for a main frame newer than the last one taken. With an
    // environment camera also takes the environment frame nearest in time to it: the newest
    // in its slot or, when that is more than half an environment frame older than the main
    // frame, the next one if it comes within that half frame (both clocks are CLOCK_MONOTONIC;
    // the main camera sets the pace). False on timeout or at the end of the main stream.
    bool next(LiveFrame& frame, double timeoutSeconds);

    bool ended() const { return main_.ended(); }
    // The environment camera ended (its last frame keeps lighting); the reason, once.
    // Read by the GL thread while next() runs on the tracking worker's.
    bool environmentEnded() const { return envEnded_.load(); }
    bool hasEnvironment() const { return env_.has_value(); }
    // The camera is unplugged or stalled and is being reopened; the reason.
    bool lost() const { return main_.state() == LatestFrameCapture::State::Lost; }
    std::string lostReason() const { return main_.lostReason(); }
    const LatestFrameCapture& main() const { return main_; }
    // Stops both threads; the main camera's failure, if any ("" when it just ended or stopped).
    std::string stop();

private:
    LatestFrameCapture main_;
    std::optional<LatestFrameCapture> env_;
    double envHalfPeriodS_ = 0;
    cv::Mat envLatest_;  // the environment's newest frame as delivered, and its time
    double envLatestS_ = 0;
    std::atomic<bool> envEnded_{false};
};

}  // namespace mirage::app
