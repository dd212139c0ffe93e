// The camera layer behind its interface, against a device double that fails the way cameras
// do: a driver that adjusts the mode asked for, sequence-number gaps (frames the driver
// dropped), ENODEV in the middle of the stream (unplugged) and a device that is missing for a
// while before it comes back; and the exposure controls: locked where offered, warned about
// where not.
#include <cerrno>
#include <cstring>
#include <thread>

#include <gtest/gtest.h>

#include "core/Error.h"
#include "core/capture/CameraControls.h"
#include "core/capture/LatestFrameCapture.h"
#include "core/capture/V4l2Camera.h"

namespace mirage {
namespace {

struct DoubleSpec {
    bool adjustRate = false;      // the driver gives 15 fps when 30 are asked
    int failAfter = -1;           // frames before dequeue fails with ENODEV
    int64_t skipAtSequence = -1;  // the driver drops the frame after this one (sequence gap)
    bool refuseManualExposure = false;
    std::vector<CameraControl> controls;
};

class CameraDouble final : public CaptureDevice {
public:
    explicit CameraDouble(DoubleSpec s) : s_(std::move(s)) {}
    std::string name() const override { return "/dev/video9 (camera double)"; }
    std::vector<CaptureMode> modes() override { return {{PixelFormat::Yuyv, 64, 48, 30}}; }
    CaptureMode configure(const CaptureMode& m) override {
        mode_ = m;
        if (s_.adjustRate) mode_.fps = 15;
        return mode_;
    }
    void start() override {}
    void stop() override {}
    bool dequeue(RawFrame& f, int) override {
        if (s_.failAfter >= 0 && served_ >= s_.failAfter)
            throw Error(name() +
                        ": cannot dequeue a frame (camera unplugged?): " + std::strerror(ENODEV));
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
        buffer_.assign(64 * 48 * 2, uint8_t(16 + served_));
        f.format = PixelFormat::Yuyv;
        f.width = 64;
        f.height = 48;
        f.bytesPerLine = 128;
        f.bytes = buffer_.data();
        f.size = buffer_.size();
        f.sequence = sequence_;
        f.deviceSeconds = 1000.0 + double(sequence_) / mode_.fps;
        sequence_ += sequence_ == s_.skipAtSequence ? 2 : 1;
        ++served_;
        return true;
    }
    std::vector<CameraControl> controls() override { return s_.controls; }
    std::optional<int64_t> setControl(CameraControlId id, int64_t v) override {
        for (auto& c : s_.controls)
            if (c.id == id) {
                if (id == CameraControlId::AutoExposure && v == 0 && s_.refuseManualExposure)
                    return c.value;  // still automatic
                c.value = std::clamp(v, c.min, c.max);
                return c.value;
            }
        return std::nullopt;
    }
    const DoubleSpec& spec() const { return s_; }

private:
    DoubleSpec s_;
    CaptureMode mode_;
    std::vector<uint8_t> buffer_;
    int served_ = 0;
    int64_t sequence_ = 0;
};

int64_t controlValue(const std::vector<CameraControl>& cs, CameraControlId id) {
    for (const auto& c : cs)
        if (c.id == id) return c.value;
    return -999;
}

TEST(CameraDouble, AdjustedModeIsUsedAndSaid) {
    DoubleSpec s;
    s.adjustRate = true;
    V4l2Camera cam(std::make_unique<CameraDouble>(s), CaptureRequest{64, 48, 30});
    EXPECT_DOUBLE_EQ(cam.mode().fps, 15);
    EXPECT_NE(cam.modeNote().find("the driver gives YUYV 64x48 at 15.00 fps"), std::string::npos)
        << cam.modeNote();
    cv::Mat bgr;
    EXPECT_TRUE(cam.read(bgr));
    EXPECT_EQ(bgr.size(), cv::Size(64, 48));

    V4l2Camera asked(std::make_unique<CameraDouble>(DoubleSpec{}), CaptureRequest{64, 48, 30});
    EXPECT_EQ(asked.modeNote(), "");
}

TEST(CameraDouble, DriverSequenceGapsCountAsDropped) {
    DoubleSpec s;
    s.skipAtSequence = 3;
    LatestFrameCapture cap(
        std::make_unique<V4l2Camera>(std::make_unique<CameraDouble>(s), CaptureRequest{64, 48, 30}),
        {});
    CapturedFrame f;
    for (int i = 0; i < 8; ++i) ASSERT_TRUE(cap.next(f, 2.0));
    EXPECT_EQ(cap.deviceDropped(), 1);
    cap.stop();
}

TEST(CameraDouble, UnpluggedCameraIsLostThenReconnected) {
    DoubleSpec flaky;
    flaky.failAfter = 5;
    int attempts = 0;
    LatestFrameCapture::Options o;
    o.retrySeconds = 0.05;  // lost for at least 0.1 s: two failed attempts
    o.sourceClockIsMonotonic = true;
    o.reopen = [&attempts]() -> std::unique_ptr<FrameSource> {
        // Missing for two attempts (the device node is gone), then back.
        if (++attempts <= 2) throw Error("camera /dev/video9 not found: is a camera plugged in?");
        return std::make_unique<V4l2Camera>(std::make_unique<CameraDouble>(DoubleSpec{}),
                                            CaptureRequest{64, 48, 30});
    };
    LatestFrameCapture cap(std::make_unique<V4l2Camera>(std::make_unique<CameraDouble>(flaky),
                                                        CaptureRequest{64, 48, 30}),
                           o);
    CapturedFrame f;
    int before = 0, after = 0;
    bool sawLost = false;
    const auto t0 = std::chrono::steady_clock::now();
    while (after < 5 && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(20)) {
        if (cap.next(f, 0.01)) {
            (cap.reconnections() > 0 ? after : before)++;
            continue;
        }
        if (cap.state() == LatestFrameCapture::State::Lost) {
            sawLost = true;
            EXPECT_NE(cap.lostReason().find("No such device"), std::string::npos)
                << cap.lostReason();
        }
    }
    EXPECT_GE(before, 1);
    EXPECT_EQ(after, 5);
    EXPECT_EQ(cap.reconnections(), 1);
    EXPECT_EQ(attempts, 3);
    EXPECT_TRUE(sawLost);
    EXPECT_LE(before, 5);
    EXPECT_EQ(cap.state(), LatestFrameCapture::State::Streaming);
    EXPECT_EQ(cap.error(), "");
}

TEST(CameraDouble, UnpluggedWithoutReopenEndsWithTheError) {
    DoubleSpec flaky;
    flaky.failAfter = 2;
    LatestFrameCapture cap(std::make_unique<V4l2Camera>(std::make_unique<CameraDouble>(flaky),
                                                        CaptureRequest{64, 48, 30}),
                           {});
    CapturedFrame f;
    while (cap.next(f, 2.0)) {
    }
    EXPECT_TRUE(cap.ended());
    EXPECT_NE(cap.error().find("No such device"), std::string::npos) << cap.error();
}

std::vector<CameraControl> uvcControls() {
    using Id = CameraControlId;
    return {{Id::AutoExposure, 0, 1, 1},     {Id::Exposure, 3, 2047, 250},
            {Id::AutoGain, 0, 1, 1},         {Id::Gain, 0, 255, 64},
            {Id::AutoWhiteBalance, 0, 1, 1}, {Id::WhiteBalance, 2800, 6500, 4600}};
}

TEST(CameraControls, LocksAtTheSettledValuesOrTheGivenOnes) {
    using Id = CameraControlId;
    DoubleSpec s;
    s.controls = uvcControls();
    CameraDouble dev(s);
    ExposureLockReport r = lockExposure(dev, {});
    EXPECT_TRUE(r.exposureLocked);
    EXPECT_TRUE(r.whiteBalanceLocked);
    EXPECT_TRUE(r.warnings.empty());
    const auto now = dev.controls();
    EXPECT_EQ(controlValue(now, Id::AutoExposure), 0);
    EXPECT_EQ(controlValue(now, Id::Exposure), 250);  // where automatic exposure had settled
    EXPECT_EQ(controlValue(now, Id::AutoGain), 0);
    EXPECT_EQ(controlValue(now, Id::AutoWhiteBalance), 0);

    CameraDouble dev2(s);
    ExposureSettings want;
    want.exposure = 100;
    want.gain = 1000;  // beyond the range: clamped, and the note says so
    want.whiteBalanceK = 5000;
    r = lockExposure(dev2, want);
    const auto set = dev2.controls();
    EXPECT_EQ(controlValue(set, Id::Exposure), 100);
    EXPECT_EQ(controlValue(set, Id::Gain), 255);
    EXPECT_EQ(controlValue(set, Id::WhiteBalance), 5000);
    bool clampNoted = false;
    for (const auto& n : r.notes)
        clampNoted |= n.find("gain 255 (asked 1000)") != std::string::npos;
    EXPECT_TRUE(clampNoted);
}

TEST(CameraControls, WarnsWhenAutoExposureCannotBeLocked) {
    DoubleSpec refusing;
    refusing.controls = uvcControls();
    refusing.refuseManualExposure = true;
    CameraDouble dev(refusing);
    ExposureLockReport r = lockExposure(dev, {});
    EXPECT_FALSE(r.exposureLocked);
    ASSERT_FALSE(r.warnings.empty());
    EXPECT_NE(r.warnings[0].find("automatic exposure cannot be switched off"), std::string::npos)
        << r.warnings[0];

    CameraDouble bare(DoubleSpec{});  // no controls at all
    r = lockExposure(bare, {});
    EXPECT_FALSE(r.exposureLocked);
    ASSERT_FALSE(r.warnings.empty());
    EXPECT_NE(r.warnings[0].find("offers no exposure control"), std::string::npos) << r.warnings[0];
}

}  // namespace
}  // namespace mirage
