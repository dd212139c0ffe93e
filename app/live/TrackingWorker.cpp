#include "app/live/TrackingWorker.h"

#include <chrono>

#include "core/Error.h"
#include "core/capture/CaptureFormat.h"

namespace mirage::app {

namespace {

std::chrono::steady_clock::time_point steadyTimePoint(double seconds) {
    return std::chrono::steady_clock::time_point(
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            std::chrono::duration<double>(seconds)));
}

}  // namespace

TrackingWorker::TrackingWorker(Step step, bool threaded)
    : step_(std::move(step)), threaded_(threaded) {
    MR_CHECK(step_ != nullptr, "TrackingWorker needs a step");
    if (threaded_) thread_ = std::thread([this] { run(); });
}

TrackingWorker::~TrackingWorker() {
    stop();
}

void TrackingWorker::stop() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    ready_.notify_all();
    if (thread_.joinable()) thread_.join();
}

void TrackingWorker::request(double startSeconds) {
    if (!threaded_) return;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        requestStart_ = startSeconds;
        ++requestId_;
    }
    wake_.notify_all();
}

void TrackingWorker::run() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stop_) {
        wake_.wait(lock, [this] { return stop_ || requestStart_.has_value(); });
        // Until the request's start; a newer request may move it, stop() ends the wait.
        while (!stop_ && requestStart_ && steadySeconds() < *requestStart_)
            wake_.wait_until(lock, steadyTimePoint(*requestStart_));
        if (stop_) break;
        if (!requestStart_) continue;
        const uint64_t id = requestId_;
        lock.unlock();
        TrackedLiveFrame item;
        Result r = Result::Timeout;
        std::exception_ptr error;
        try {
            r = step_(item, kStepTimeoutSeconds);
        } catch (...) {
            error = std::current_exception();
        }
        lock.lock();
        if (error || r == Result::Ended) {
            error_ = error;
            break;
        }
        if (r == Result::Timeout) continue;  // no camera frame yet: the request stays
        if (slot_) ++stale_;                 // never taken: this newer frame replaces it
        slot_ = std::move(item);
        // Satisfied, unless a newer request came while tracking (it wants a newer frame).
        if (requestId_ == id) requestStart_.reset();
        ready_.notify_all();
    }
    ended_ = true;
    ready_.notify_all();
}

TrackingWorker::Result TrackingWorker::take(TrackedLiveFrame& out, double timeoutSeconds) {
    if (!threaded_) {
        if (ended_) return Result::Ended;
        const Result r = step_(out, timeoutSeconds);
        if (r == Result::Ended) ended_ = true;
        return r;
    }
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait_for(lock, std::chrono::duration<double>(timeoutSeconds),
                    [this] { return slot_.has_value() || ended_; });
    if (slot_) {
        out = std::move(*slot_);
        slot_.reset();
        out.frame.main.droppedBefore += stale_;
        return Result::Frame;
    }
    if (ended_) {
        if (error_) std::rethrow_exception(error_);
        return Result::Ended;
    }
    return Result::Timeout;
}

void TrackingWorker::discard() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!slot_) return;
    ++stale_;
    slot_.reset();
}

int64_t TrackingWorker::staleDropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return stale_;
}

}  // namespace mirage::app
