#include "app/live/LiveRecorder.h"

#include "app/live/LiveInputs.h"
#include "core/Log.h"

namespace mirage::app {

namespace fs = std::filesystem;

LiveRecorder::LiveRecorder(fs::path firstDir, fs::path calibration, fs::path board,
                           LiveRecording::Options options, std::string scene)
    : firstDir_(std::move(firstDir)),
      calibration_(std::move(calibration)),
      board_(std::move(board)),
      options_(std::move(options)),
      scene_(std::move(scene)) {}

LiveRecorder::~LiveRecorder() {
    try {
        stop();
    } catch (...) {
        // Every appended frame is on disk already.
    }
}

void LiveRecorder::start() {
    if (recording_) return;
    const fs::path dir =
        !firstDir_.empty() && !firstUsed_ ? firstDir_ : fs::path(timestampName("live-", ""));
    firstUsed_ = true;
    recording_ = std::make_unique<LiveRecording>(dir, calibration_, board_, options_);
    waitsForEnvironment_ = 0;
    spdlog::info("live: recording into {}{}", dir.string(),
                 recording_->hasEnvironment() ? " (with the environment camera)" : "");
}

void LiveRecorder::append(const cv::Mat& bgr, double seconds, const PoseRow& pose,
                          const cv::Mat& envBgr, double envSeconds) {
    if (!recording_ || bgr.empty()) return;
    if (!recording_->hasEnvironment())
        recording_->append(bgr, seconds, pose);
    else if (envBgr.empty())
        ++waitsForEnvironment_;
    else
        recording_->append(bgr, seconds, pose, envBgr, envSeconds);
}

void LiveRecorder::stop() {
    if (!recording_) return;
    std::unique_ptr<LiveRecording> r = std::move(recording_);
    lastDir_ = r->dir();
    lastFrames_ = r->frames();
    r->close();
    if (waitsForEnvironment_ > 0)
        spdlog::warn(
            "live: the first {} processed frames were not recorded: the environment camera had "
            "delivered no frame yet",
            waitsForEnvironment_);
    if (lastFrames_ == 0) {
        // A session without footage: nothing could replay it; the folder was new (or empty).
        std::error_code ec;
        fs::remove_all(lastDir_, ec);
        spdlog::warn("live: stopped before the first frame was recorded; {} not kept",
                     lastDir_.string());
        return;
    }
    spdlog::info(
        "live: recorded {} frames into {} (replay: mirage replay {} --scene {} --poses "
        "{}/poses.csv -o OUT)",
        lastFrames_, lastDir_.string(), lastDir_.string(), scene_, lastDir_.string());
}

int LiveRecorder::frames() const {
    return recording_ ? recording_->frames() : 0;
}

const fs::path& LiveRecorder::dir() const {
    static const fs::path none;
    return recording_ ? recording_->dir() : none;
}

}  // namespace mirage::app
