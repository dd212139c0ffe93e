// The capture thread's latest-frame hand-off (core/capture/LatestFrameCapture.h): a slow consumer
// gets the newest frame and the skipped ones are counted as dropped, never queued; a fast one
// gets every frame; a failing source ends the stream with its error.
#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "core/Error.h"
#include "core/capture/LatestFrameCapture.h"

namespace mirage {
namespace {

// N frames of 4x4 pixels whose first byte is the frame number; throws after `failAfter`.
class CountingSource final : public FrameSource {
public:
    CountingSource(int n, int failAfter = -1) : n_(n), failAfter_(failAfter) {}
    bool read(cv::Mat& bgr) override {
        if (i_ == failAfter_) throw Error("camera lost (test)");
        if (i_ >= n_) return false;
        bgr = cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(0));
        bgr.at<cv::Vec3b>(0, 0)[0] = uint8_t(i_);
        ++i_;
        return true;
    }
    int frameCount() const override { return n_; }

private:
    int n_, failAfter_, i_ = 0;
};

TEST(LatestFrameCapture, SlowConsumerGetsTheNewestFrameAndDropsAreCounted) {
    LatestFrameCapture::Options o;
    o.paceFps = 200;  // a frame every 5 ms
    LatestFrameCapture cap(std::make_unique<CountingSource>(60), o);
    std::vector<int64_t> seen;
    CapturedFrame f;
    while (cap.next(f, 2.0)) {
        EXPECT_EQ(int(f.bgr.at<cv::Vec3b>(0, 0)[0]), int(f.sequence));  // the frame it says
        EXPECT_EQ(f.droppedBefore, f.sequence - int64_t(seen.size()));
        if (!seen.empty()) {
            EXPECT_GT(f.sequence, seen.back());
        }
        seen.push_back(f.sequence);
        std::this_thread::sleep_for(std::chrono::milliseconds(22));  // slower than the camera
    }
    EXPECT_TRUE(cap.ended());
    EXPECT_EQ(cap.error(), "");
    EXPECT_EQ(cap.delivered(), 60);
    EXPECT_EQ(cap.dropped() + int64_t(seen.size()), 60);
    // About one frame in four or five is taken; a queue would have delivered all 60.
    EXPECT_LT(seen.size(), 30u);
    EXPECT_GT(cap.dropped(), 30);
}

TEST(LatestFrameCapture, PacedAtTheFrameRate) {
    LatestFrameCapture::Options o;
    o.paceFps = 20;  // 20 frames: 0.95 s from the first to the last
    LatestFrameCapture cap(std::make_unique<CountingSource>(20), o);
    CapturedFrame f;
    std::vector<double> times;
    while (cap.next(f, 2.0)) times.push_back(f.captureSeconds);
    ASSERT_EQ(times.size(), 20u);  // a consumer that keeps up loses nothing
    EXPECT_EQ(cap.dropped(), 0);
    EXPECT_NEAR(times.back() - times.front(), 19 / 20.0, 0.1);
}

TEST(LatestFrameCapture, FailingSourceEndsWithItsError) {
    LatestFrameCapture cap(std::make_unique<CountingSource>(10, 3), {});
    CapturedFrame f;
    int n = 0;
    while (cap.next(f, 2.0)) ++n;
    EXPECT_LE(n, 3);
    EXPECT_TRUE(cap.ended());
    EXPECT_NE(cap.error().find("camera lost"), std::string::npos);
}

TEST(LatestFrameCapture, StopInterruptsAPacedWait) {
    LatestFrameCapture::Options o;
    o.paceFps = 0.01;  // the second frame would come after 100 s
    auto t0 = std::chrono::steady_clock::now();
    {
        LatestFrameCapture cap(std::make_unique<CountingSource>(5), o);
        CapturedFrame f;
        EXPECT_TRUE(cap.next(f, 2.0));
        EXPECT_FALSE(cap.next(f, 0.05));  // times out: no frame yet, not ended
        EXPECT_FALSE(cap.ended());
    }
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
}

}  // namespace
}  // namespace mirage
