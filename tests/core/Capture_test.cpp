// Live capture without a webcam: mode choice, YUYV/MJPEG conversion, timestamps and dropped
// frames, the camera pipeline over a recorded video posing as a device, recording to a session,
// and clear errors when there is no camera.
#include <atomic>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/capture/CaptureFormat.h"
#include "core/capture/SessionRecorder.h"
#include "core/capture/V4l2Camera.h"
#include "core/capture/V4l2Device.h"
#include "core/capture/VideoFileCaptureDevice.h"
#include "core/image/ImageIO.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

namespace fs = std::filesystem;
using Fmt = CaptureRequest::Format;

// A typical USB 2 webcam: YUYV is bandwidth-limited at large sizes, MJPEG is not.
std::vector<CaptureMode> webcamModes() {
    return {{PixelFormat::Yuyv, 640, 480, 30},   {PixelFormat::Yuyv, 1280, 720, 10},
            {PixelFormat::Yuyv, 1920, 1080, 5},  {PixelFormat::Mjpeg, 640, 480, 30},
            {PixelFormat::Mjpeg, 1280, 720, 30}, {PixelFormat::Mjpeg, 1280, 720, 15},
            {PixelFormat::Mjpeg, 1920, 1080, 30}};
}

void expectMode(const std::optional<CaptureMode>& m, PixelFormat f, int w, int h, double fps) {
    ASSERT_TRUE(m.has_value());
    EXPECT_EQ(m->format, f);
    EXPECT_EQ(m->width, w);
    EXPECT_EQ(m->height, h);
    EXPECT_DOUBLE_EQ(m->fps, fps);
}

TEST(CaptureMode, ChoosesSizeThenRateThenFormat) {
    const auto modes = webcamModes();
    // YUYV cannot do 720p at 30 fps: MJPEG.
    expectMode(chooseCaptureMode(modes, {1280, 720, 30, Fmt::Auto}), PixelFormat::Mjpeg, 1280, 720,
               30);
    // Both can do VGA at 30: uncompressed YUYV.
    expectMode(chooseCaptureMode(modes, {640, 480, 30, Fmt::Auto}), PixelFormat::Yuyv, 640, 480,
               30);
    // 10 fps asked: YUYV reaches it.
    expectMode(chooseCaptureMode(modes, {1280, 720, 10, Fmt::Auto}), PixelFormat::Yuyv, 1280, 720,
               10);
    // 12 fps asked: MJPEG at 15 is the lowest rate reaching it.
    expectMode(chooseCaptureMode(modes, {1280, 720, 12, Fmt::Auto}), PixelFormat::Mjpeg, 1280, 720,
               15);
    // 29.97 counts as 30.
    expectMode(chooseCaptureMode(modes, {640, 480, 29.97, Fmt::Auto}), PixelFormat::Yuyv, 640, 480,
               30);
    // A size not offered: the nearest with the same aspect ratio (16:9), not the nearest area.
    expectMode(chooseCaptureMode(modes, {1000, 560, 30, Fmt::Auto}), PixelFormat::Mjpeg, 1280, 720,
               30);
    // Forced YUYV at 720p: the fastest it has.
    expectMode(chooseCaptureMode(modes, {1280, 720, 30, Fmt::Yuyv}), PixelFormat::Yuyv, 1280, 720,
               10);
    // Nothing to choose from.
    EXPECT_FALSE(chooseCaptureMode({}, {}).has_value());
    EXPECT_FALSE(
        chooseCaptureMode({{PixelFormat::Mjpeg, 640, 480, 30}}, {640, 480, 30, Fmt::Yuyv}));
}

// BT.601 limited range, written out: the convention webcams use for YUYV.
cv::Vec3b referenceYuvToBgr(int y, int u, int v) {
    const double c = 1.164 * (y - 16), d = u - 128, e = v - 128;
    auto cl = [](double x) { return uchar(std::clamp(std::lround(x), 0L, 255L)); };
    return {cl(c + 2.018 * d), cl(c - 0.391 * d - 0.813 * e), cl(c + 1.596 * e)};
}

TEST(CaptureFormat, YuyvToBgrIsBt601LimitedRange) {
    const int w = 8, h = 4;
    cv::RNG rng(7);
    std::vector<uint8_t> yuyv(size_t(w * h * 2));
    for (auto& b : yuyv) b = uchar(rng.uniform(16, 236));
    RawFrame f{PixelFormat::Yuyv, w, h, 2 * w, yuyv.data(), yuyv.size(), -1, -1};
    cv::Mat bgr;
    ASSERT_TRUE(convertToBgr(f, bgr));
    ASSERT_EQ(bgr.type(), CV_8UC3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const uint8_t* p = yuyv.data() + (y * w + (x & ~1)) * 2;
            const cv::Vec3b want = referenceYuvToBgr(p[(x & 1) ? 2 : 0], p[1], p[3]);
            const cv::Vec3b got = bgr.at<cv::Vec3b>(y, x);
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 2) << x << "," << y;
        }
    // Limited range: Y=235 is white, Y=16 black.
    std::vector<uint8_t> wb = {235, 128, 16, 128};
    ASSERT_TRUE(convertToBgr({PixelFormat::Yuyv, 2, 1, 4, wb.data(), 4, -1, -1}, bgr));
    EXPECT_GE(bgr.at<cv::Vec3b>(0, 0)[1], 254);
    EXPECT_LE(bgr.at<cv::Vec3b>(0, 1)[1], 1);
}

TEST(CaptureFormat, YuyvHonoursStrideAndRejectsShortFrames) {
    cv::Mat img(6, 10, CV_8UC3);
    cv::randu(img, 0, 255);
    const std::vector<uint8_t> packed = bgrToYuyv(img);
    const int stride = 10 * 2 + 12;
    std::vector<uint8_t> padded(size_t(stride * 6), 0xEE);
    for (int y = 0; y < 6; ++y) std::copy_n(packed.data() + y * 20, 20, padded.data() + y * stride);
    cv::Mat a, b;
    ASSERT_TRUE(
        convertToBgr({PixelFormat::Yuyv, 10, 6, 20, packed.data(), packed.size(), -1, -1}, a));
    ASSERT_TRUE(
        convertToBgr({PixelFormat::Yuyv, 10, 6, stride, padded.data(), padded.size(), -1, -1}, b));
    EXPECT_TRUE(std::isinf(test::psnr(a, b, 255)));
    // One byte short, odd width, stride too small, no data: all rejected.
    EXPECT_FALSE(
        convertToBgr({PixelFormat::Yuyv, 10, 6, 20, packed.data(), packed.size() - 1, -1, -1}, a));
    EXPECT_TRUE(a.empty());
    EXPECT_FALSE(
        convertToBgr({PixelFormat::Yuyv, 9, 6, 20, packed.data(), packed.size(), -1, -1}, a));
    EXPECT_FALSE(
        convertToBgr({PixelFormat::Yuyv, 10, 6, 18, packed.data(), packed.size(), -1, -1}, a));
    EXPECT_FALSE(convertToBgr({PixelFormat::Yuyv, 10, 6, 20, nullptr, 0, -1, -1}, a));
}

cv::Mat smoothImage(int w, int h, int seed) {
    cv::Mat img(h, w, CV_8UC3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            img.at<cv::Vec3b>(y, x) =
                cv::Vec3b(uchar(x * 255 / w), uchar(y * 255 / h), uchar(seed * 40));
    cv::circle(img, {w / 3 + seed * 5, h / 2}, h / 5, cv::Scalar(30, 200, 240), cv::FILLED);
    return img;
}

TEST(CaptureFormat, YuyvRoundTripAndMjpeg) {
    const cv::Mat img = smoothImage(64, 48, 1);
    const std::vector<uint8_t> yuyv = bgrToYuyv(img);
    cv::Mat back;
    ASSERT_TRUE(
        convertToBgr({PixelFormat::Yuyv, 64, 48, 128, yuyv.data(), yuyv.size(), -1, -1}, back));
    EXPECT_GT(test::psnr(back, img, 255), 30.0);  // 4:2:2 chroma (sharp colour edges) only
    EXPECT_LT(test::psnr(back, smoothImage(64, 48, 3), 255), 25.0);  // and it can fail

    std::vector<uint8_t> jpeg;
    cv::imencode(".jpg", img, jpeg);
    ASSERT_TRUE(
        convertToBgr({PixelFormat::Mjpeg, 64, 48, 0, jpeg.data(), jpeg.size(), -1, -1}, back));
    EXPECT_GT(test::psnr(back, img, 255), 30.0);
    // A JPEG of another size than negotiated, and garbage, are dropped.
    EXPECT_FALSE(
        convertToBgr({PixelFormat::Mjpeg, 32, 48, 0, jpeg.data(), jpeg.size(), -1, -1}, back));
    std::vector<uint8_t> garbage(500, 0x5A);
    EXPECT_FALSE(convertToBgr(
        {PixelFormat::Mjpeg, 64, 48, 0, garbage.data(), garbage.size(), -1, -1}, back));
}

TEST(CaptureFormat, FrameClockPrefersTheDriverClock) {
    FrameClock clock;
    RawFrame f;
    f.deviceSeconds = 10.0;
    f.sequence = 0;
    EXPECT_DOUBLE_EQ(clock.stamp(f, 500.0), 10.0);
    f.deviceSeconds = 10.033;
    f.sequence = 3;  // frames 1 and 2 dropped by the driver
    EXPECT_DOUBLE_EQ(clock.stamp(f, 500.1), 10.033);
    EXPECT_EQ(clock.droppedFrames(), 2);
    EXPECT_TRUE(clock.usingDeviceClock());
    // The driver clock goes backwards: host clock from now on, still increasing.
    f.deviceSeconds = 5.0;
    f.sequence = 4;
    EXPECT_DOUBLE_EQ(clock.stamp(f, 500.2), 500.2);
    EXPECT_FALSE(clock.usingDeviceClock());
    f.deviceSeconds = 10.1;
    EXPECT_DOUBLE_EQ(clock.stamp(f, 500.2), 500.2 + 1e-6);

    FrameClock noDriver;
    RawFrame g;
    EXPECT_DOUBLE_EQ(noDriver.stamp(g, 3.0), 3.0);
    EXPECT_DOUBLE_EQ(noDriver.stamp(g, 3.5), 3.5);
    EXPECT_EQ(noDriver.droppedFrames(), 0);
}

// A short recorded video to pose as a camera.
// Each test gets its own copy: ctest may run tests in parallel processes.
fs::path recordedVideo(const std::string& name) {
    const fs::path dir = test::outputDir(name);
    SessionWriter::Options o;
    o.fps = 20;
    o.imageSequence = true;  // lossless: the camera path's own loss is what is measured
    Session meta;
    meta.board = "";
    SessionWriter w(dir, meta, o);
    for (int i = 0; i < 6; ++i) w.append({smoothImage(64, 48, i)}, {}, std::nullopt);
    w.close();
    return dir / "main";
}

TEST(V4l2Camera, PipelineOverARecordedVideo) {
    const fs::path video = recordedVideo("capture_source_pipeline");
    for (const Fmt fmt : {Fmt::Yuyv, Fmt::Mjpeg}) {
        VideoFileCaptureDevice::Options o;
        o.fps = 20;
        o.startSeconds = 50.0;
        o.dropAfter = {2};         // the "driver" drops frame 3
        o.yuyvStridePadding = 16;  // and pads rows
        V4l2Camera cam(std::make_unique<VideoFileCaptureDevice>(video, o), {64, 48, 20, fmt});
        EXPECT_EQ(cam.mode().format, fmt == Fmt::Yuyv ? PixelFormat::Yuyv : PixelFormat::Mjpeg);
        std::vector<double> times;
        cv::Mat frame;
        int i = 0;
        while (cam.read(frame)) {
            EXPECT_GT(test::psnr(frame, smoothImage(64, 48, i), 255), 28.0) << i;
            times.push_back(*cam.lastTimestamp());
            ++i;
        }
        EXPECT_EQ(i, 6);
        ASSERT_EQ(times.size(), 6u);
        EXPECT_DOUBLE_EQ(times[0], 50.0);
        EXPECT_DOUBLE_EQ(times[2], 50.1);
        EXPECT_DOUBLE_EQ(times[3], 50.2);  // sequence 4: one frame period skipped
        EXPECT_EQ(cam.droppedFrames(), 1);
        EXPECT_EQ(cam.corruptFrames(), 0);
    }
}

TEST(V4l2Camera, ClearErrorsWithoutADevice) {
    auto message = [](const std::string& dev) {
        try {
            V4l2Camera cam(dev, CaptureRequest{});
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("opened");
    };
    EXPECT_NE(message("/dev/video-mirage-none").find("not found"), std::string::npos);
    EXPECT_NE(message("/dev/null").find("not a V4L2 device"), std::string::npos);
    EXPECT_NE(message(test::testDataDir().string()).find("not a device file"), std::string::npos);
    EXPECT_EQ(v4l2DevicePath("2"), "/dev/video2");
    EXPECT_EQ(v4l2DevicePath("/dev/video1"), "/dev/video1");
}

TEST(SessionRecorder, LiveRecordingReplaysExactly) {
    const fs::path video = recordedVideo("capture_source_recorder");
    VideoFileCaptureDevice::Options o;
    o.fps = 20;
    o.startSeconds = 7.0;
    V4l2Camera cam(std::make_unique<VideoFileCaptureDevice>(video, o), {64, 48, 20, Fmt::Yuyv});
    auto env = openFrames(video);  // a second camera without a clock

    const fs::path dir = test::outputDir("capture_recording");
    SessionRecorder::Options ro;
    ro.writer.fps = 20;
    ro.writer.imageSequence = true;  // lossless, so replay must equal what was seen live
    ro.maxFrames = 5;
    Session meta;
    meta.board = "";
    SessionRecorder rec(dir, meta, {&cam, env.get()}, ro);
    std::vector<cv::Mat> seen;
    std::atomic<bool> stop{false};
    EXPECT_EQ(
        rec.run(&stop, [&](const std::vector<cv::Mat>& imgs) { seen.push_back(imgs[0].clone()); }),
        5);
    rec.close();

    SessionReadReport report;
    const Session s = readSession(dir, &report);
    EXPECT_TRUE(report.ok());
    ASSERT_EQ(s.frames.size(), 5u);
    EXPECT_EQ(s.cameras[1].name, "env");
    EXPECT_DOUBLE_EQ(s.frames[4].timestamps[0], 7.2);  // the device clock, kept exactly
    EXPECT_DOUBLE_EQ(s.frames[4].timestamps[1], 4 / 20.0);
    auto replay = openCameraFrames(s, "main");
    cv::Mat f;
    for (size_t i = 0; i < seen.size(); ++i) {
        ASSERT_TRUE(replay->read(f));
        EXPECT_TRUE(std::isinf(test::psnr(f, seen[i], 255))) << i;
    }
    EXPECT_FALSE(replay->read(f));

    // The stop flag ends a recording at once.
    const fs::path dir2 = test::outputDir("capture_recording_stop");
    auto again = openFrames(video);
    SessionRecorder rec2(dir2, meta, {again.get()}, {});
    stop = true;
    EXPECT_EQ(rec2.run(&stop), 0);
    EXPECT_THROW(SessionRecorder(test::outputDir("capture_recording_bad"), meta, {}, {}), Error);
}

}  // namespace
}  // namespace mirage
