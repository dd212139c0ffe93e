#pragma once
// The record stage of a live session, part two: --record and the HUD's record button. The frames
// the loop processed, with their live poses (and the environment frame that lit each), recorded
// as a session (core/capture/LiveRecording.h) that `mirage replay` reproduces.
//
// Interrupted (SIGINT, SIGTERM, the window closed) the recording is closed like any other: its
// video ends with its Segment size and duration written, its frames.csv and poses.csv hold a row
// per frame. A recording stopped before its first frame is removed: it would be a session
// without footage (an empty main.mkv), which nothing can play.
#include <filesystem>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "core/capture/LiveRecording.h"
#include "core/session/PosesCsv.h"

namespace mirage::app {

class LiveRecorder {
public:
    // `firstDir`: the folder of the first recording (--record; empty: a timestamped name);
    // later ones (the HUD's record button) get timestamped names. `scene` is only named in the
    // log line that says how to replay a recording.
    LiveRecorder(std::filesystem::path firstDir, std::filesystem::path calibration,
                 std::filesystem::path board, LiveRecording::Options options, std::string scene);
    ~LiveRecorder();
    LiveRecorder(const LiveRecorder&) = delete;
    LiveRecorder& operator=(const LiveRecorder&) = delete;

    void start();  // throws FileError (a folder in the way, a full disk); nothing is recording then
    void stop();   // closes the recording (removes it when it has no frame); no-op when stopped
    bool recording() const { return recording_ != nullptr; }

    // One processed frame (8-bit BGR, capture time in seconds on CLOCK_MONOTONIC) with its pose
    // decision. With an environment camera `envBgr` is its newest frame delivered (used by the
    // renderer or not: a frame it refused is refused again in replay with the same
    // calibration) and `envSeconds` that frame's time; main frames processed before the
    // environment camera's first frame are not recorded (counted, said at stop()).
    void append(const cv::Mat& bgr, double seconds, const PoseRow& pose, const cv::Mat& envBgr,
                double envSeconds);

    int frames() const;                                                // of the current recording
    const std::filesystem::path& dir() const;                          // of the current recording
    const std::filesystem::path& lastDir() const { return lastDir_; }  // the last one stopped
    int lastFrames() const { return lastFrames_; }

private:
    std::filesystem::path firstDir_, calibration_, board_;
    LiveRecording::Options options_;
    std::string scene_;
    bool firstUsed_ = false;
    std::unique_ptr<LiveRecording> recording_;
    int waitsForEnvironment_ = 0;
    std::filesystem::path lastDir_;
    int lastFrames_ = 0;
};

}  // namespace mirage::app
