#include "core/capture/LatestFrameCapture.h"

#include <chrono>
#include <exception>

#include "core/Error.h"
#include "core/capture/CaptureFormat.h"

namespace mirage {

LatestFrameCapture::LatestFrameCapture(std::unique_ptr<FrameSource> source, Options options)
    : source_(std::move(source)), options_(options) {
    MR_CHECK(source_ != nullptr, "LatestFrameCapture needs a source");
    MR_CHECK(options_.paceFps >= 0, "LatestFrameCapture: negative frame rate");
    thread_ = std::thread([this] { run(); });
}

LatestFrameCapture::~LatestFrameCapture() {
    stop();
}

void LatestFrameCapture::stop() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    ready_.notify_all();
    if (thread_.joinable()) thread_.join();
}

void LatestFrameCapture::run() {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    std::optional<double> firstSourceTime;
    for (int64_t i = 0;; ++i) {
        CapturedFrame f;
        try {
            if (!source_->read(f.bgr)) break;
        } catch (const std::exception& e) {
            if (!options_.reopen) {
                std::lock_guard<std::mutex> lock(mutex_);
                error_ = e.what();
                break;
            }
            if (!reconnect(e.what())) break;
            --i;  // no frame this round
            continue;
        }
        f.problem = source_->lastProblem();
        f.sequence = i;
        const std::optional<double> sourceTime = source_->lastTimestamp();
        // Pacing: a stand-in waits until the moment a camera would have delivered this frame.
        // The wait is interruptible by stop().
        std::optional<Clock::time_point> due;
        if (options_.paceBySourceTime && sourceTime) {
            if (!firstSourceTime) firstSourceTime = sourceTime;
            due = start + std::chrono::duration_cast<Clock::duration>(
                              std::chrono::duration<double>(*sourceTime - *firstSourceTime));
        } else if (options_.paceFps > 0) {
            due = start + std::chrono::duration_cast<Clock::duration>(
                              std::chrono::duration<double>(double(i) / options_.paceFps));
        }
        std::unique_lock<std::mutex> lock(mutex_);
        if (due && wake_.wait_until(lock, *due, [this] { return stop_; })) break;
        if (stop_) break;
        f.captureSeconds =
            options_.sourceClockIsMonotonic && sourceTime ? *sourceTime : steadySeconds();
        deviceDropped_ = deviceDroppedBase_ + source_->deviceDroppedFrames();
        if (slot_) ++dropped_;  // never taken: the newer frame replaces it
        slot_ = std::move(f);
        ++delivered_;
        lock.unlock();
        ready_.notify_all();
    }
    std::lock_guard<std::mutex> lock(mutex_);
    ended_ = true;
    ready_.notify_all();
}

bool LatestFrameCapture::reconnect(const std::string& reason) {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        lost_ = true;
        lostReason_ = reason;
        deviceDroppedBase_ = deviceDropped_;
    }
    ready_.notify_all();
    source_.reset();  // close the failed device before opening it again
    for (;;) {
        {
            std::unique_lock<std::mutex> lock(mutex_);
            if (wake_.wait_for(lock, std::chrono::duration<double>(options_.retrySeconds),
                               [this] { return stop_; }))
                return false;
        }
        try {
            source_ = options_.reopen();
        } catch (const std::exception& e) {
            std::lock_guard<std::mutex> lock(mutex_);
            lostReason_ = reason + " (reconnecting: " + e.what() + ")";
            continue;
        }
        if (!source_) continue;
        std::lock_guard<std::mutex> lock(mutex_);
        lost_ = false;
        ++reconnections_;
        return true;
    }
}

LatestFrameCapture::State LatestFrameCapture::state() const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (ended_ && !slot_) return State::Ended;
    return lost_ ? State::Lost : State::Streaming;
}
std::string LatestFrameCapture::lostReason() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return lostReason_;
}
int LatestFrameCapture::reconnections() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return reconnections_;
}
int64_t LatestFrameCapture::deviceDropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return deviceDropped_;
}

bool LatestFrameCapture::next(CapturedFrame& frame, double timeoutSeconds) {
    std::unique_lock<std::mutex> lock(mutex_);
    const bool got = ready_.wait_for(lock, std::chrono::duration<double>(timeoutSeconds),
                                     [this] { return slot_.has_value() || ended_ || stop_; });
    if (!got || !slot_) return false;
    frame = std::move(*slot_);
    frame.droppedBefore = dropped_;
    frame.deviceDroppedBefore = deviceDropped_;
    slot_.reset();
    return true;
}

bool LatestFrameCapture::ended() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return ended_ && !slot_;
}
std::string LatestFrameCapture::error() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return error_;
}
int64_t LatestFrameCapture::delivered() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return delivered_;
}
int64_t LatestFrameCapture::dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
}

}  // namespace mirage
