// V4l2Device against a fake V4L2 driver (core/capture/V4l2Kernel.h): the device's own streaming,
// timing and error handling, below the CaptureDevice interface the camera double of
// CameraDouble_test.cpp replaces. The fake answers the ioctls a UVC webcam answers, keeps the
// buffer queue as the kernel does (a buffer is filled only while queued), and fails as cameras
// fail: EAGAIN after poll() woke, ENODEV once unplugged, a size and rate it adjusts, a buffer
// flagged bad, a sequence gap, a metadata node without video capture.
#include <gtest/gtest.h>

#include <sys/mman.h>
#include <cerrno>
#include <cstring>
#include <deque>
#include <map>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/capture/CaptureFormat.h"
#include "core/capture/V4l2Camera.h"
#include "core/capture/V4l2Device.h"
#include "tests/support/TestSupport.h"

namespace mirage::test {
namespace {

class FakeDriver final : public V4l2Kernel {
public:
    struct Mode {
        uint32_t fourcc, width, height;
        std::vector<uint32_t> fps;
    };
    // What happens at each VIDIOC_DQBUF (or poll), in order; after the script, frames.
    enum class Event {
        Frame,
        EagainAfterWake,  // poll() said ready, DQBUF finds no buffer
        ErrorFlagged,     // a frame with V4L2_BUF_FLAG_ERROR
        SequenceGap,      // the driver dropped two frames before this one
        Timeout,          // poll() times out
        Unplugged,        // ENODEV from here on
    };

    std::string card = "Fake Webcam";
    uint32_t capabilities = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
    std::vector<Mode> modes = {{V4L2_PIX_FMT_MJPEG, 640, 480, {30, 15}},
                               {V4L2_PIX_FMT_YUYV, 640, 480, {10}},
                               {V4L2_PIX_FMT_MJPEG, 320, 240, {30}}};
    uint32_t forcedWidth = 0, forcedHeight = 0;  // S_FMT answers with this size when set
    uint32_t forcedFps = 0;                      // S_PARM answers with this rate when set
    bool monotonicClock = true;
    bool eagainForever = false;
    std::deque<Event> script;
    // Controls: UVC's exposure menu offers manual (1) and aperture priority (3), not auto (0).
    std::map<uint32_t, int32_t> controls = {
        {V4L2_CID_EXPOSURE_AUTO, V4L2_EXPOSURE_APERTURE_PRIORITY},
        {V4L2_CID_EXPOSURE_ABSOLUTE, 156}};

    // What the device did, for the tests to check.
    int opened = 0, closed = 0, unmapped = 0, dequeuedWithNothingQueued = 0;
    uint32_t width = 0, height = 0, fourcc = 0;

    int open(const std::string& path, v4l2_capability& cap) override {
        if (path.rfind("/dev/fake", 0) != 0) throw Error("camera " + path + " not found");
        ++opened;
        cap = v4l2_capability{};
        std::snprintf(reinterpret_cast<char*>(cap.card), sizeof cap.card, "%s", card.c_str());
        cap.capabilities = capabilities | V4L2_CAP_DEVICE_CAPS;
        cap.device_caps = capabilities;
        return kFd;
    }

    int ioctl(int fd, unsigned long request, void* arg) override {
        if (fd != kFd) return fail(EBADF);
        if (unplugged_) return fail(ENODEV);
        switch (request) {
            case VIDIOC_ENUM_FMT: {
                auto& f = *static_cast<v4l2_fmtdesc*>(arg);
                std::vector<uint32_t> formats;
                for (const Mode& m : modes)
                    if (std::find(formats.begin(), formats.end(), m.fourcc) == formats.end())
                        formats.push_back(m.fourcc);
                if (f.index >= formats.size()) return fail(EINVAL);
                f.pixelformat = formats[f.index];
                f.flags = 0;
                return 0;
            }
            case VIDIOC_ENUM_FRAMESIZES: {
                auto& s = *static_cast<v4l2_frmsizeenum*>(arg);
                uint32_t k = 0;
                for (const Mode& m : modes)
                    if (m.fourcc == s.pixel_format && k++ == s.index) {
                        s.type = V4L2_FRMSIZE_TYPE_DISCRETE;
                        s.discrete = {m.width, m.height};
                        return 0;
                    }
                return fail(EINVAL);
            }
            case VIDIOC_ENUM_FRAMEINTERVALS: {
                auto& iv = *static_cast<v4l2_frmivalenum*>(arg);
                for (const Mode& m : modes)
                    if (m.fourcc == iv.pixel_format && m.width == iv.width &&
                        m.height == iv.height && iv.index < m.fps.size()) {
                        iv.type = V4L2_FRMIVAL_TYPE_DISCRETE;
                        iv.discrete = {1, m.fps[iv.index]};
                        return 0;
                    }
                return fail(EINVAL);
            }
            case VIDIOC_S_FMT: {
                if (streaming_) return fail(EBUSY);
                auto& f = *static_cast<v4l2_format*>(arg);
                // A driver adjusts what it cannot give to what it can, and says so in the reply.
                if (forcedWidth > 0) {
                    f.fmt.pix.width = forcedWidth;
                    f.fmt.pix.height = forcedHeight;
                }
                width = f.fmt.pix.width;
                height = f.fmt.pix.height;
                fourcc = f.fmt.pix.pixelformat;
                f.fmt.pix.bytesperline = fourcc == V4L2_PIX_FMT_YUYV ? 2 * width : 0;
                f.fmt.pix.sizeimage = 2 * width * height;
                return 0;
            }
            case VIDIOC_S_PARM: {
                auto& p = *static_cast<v4l2_streamparm*>(arg);
                if (forcedFps > 0) p.parm.capture.timeperframe = {1, forcedFps};
                return 0;
            }
            case VIDIOC_REQBUFS: {
                auto& r = *static_cast<v4l2_requestbuffers*>(arg);
                if (r.memory != V4L2_MEMORY_MMAP) return fail(EINVAL);
                buffers_.assign(std::min<uint32_t>(r.count, 8),
                                std::vector<uint8_t>(2 * width * height));
                queued_.clear();
                r.count = uint32_t(buffers_.size());
                return 0;
            }
            case VIDIOC_QUERYBUF: {
                auto& b = *static_cast<v4l2_buffer*>(arg);
                if (b.index >= buffers_.size()) return fail(EINVAL);
                b.length = uint32_t(buffers_[b.index].size());
                b.m.offset = b.index * kPage;
                return 0;
            }
            case VIDIOC_QBUF: {
                auto& b = *static_cast<v4l2_buffer*>(arg);
                if (b.index >= buffers_.size() ||
                    std::find(queued_.begin(), queued_.end(), b.index) != queued_.end())
                    return fail(EINVAL);
                queued_.push_back(b.index);
                return 0;
            }
            case VIDIOC_STREAMON:
                streaming_ = true;
                return 0;
            case VIDIOC_STREAMOFF:
                streaming_ = false;
                queued_.clear();
                return 0;
            case VIDIOC_DQBUF:
                return dequeue(*static_cast<v4l2_buffer*>(arg));
            case VIDIOC_QUERYCTRL: {
                auto& q = *static_cast<v4l2_queryctrl*>(arg);
                if (!controls.count(q.id)) return fail(EINVAL);
                q.minimum = q.id == V4L2_CID_EXPOSURE_AUTO ? 0 : 3;
                q.maximum = q.id == V4L2_CID_EXPOSURE_AUTO ? 3 : 2047;
                q.flags = 0;
                return 0;
            }
            case VIDIOC_G_CTRL: {
                auto& c = *static_cast<v4l2_control*>(arg);
                if (!controls.count(c.id)) return fail(EINVAL);
                c.value = controls[c.id];
                return 0;
            }
            case VIDIOC_S_CTRL: {
                auto& c = *static_cast<v4l2_control*>(arg);
                if (!controls.count(c.id)) return fail(EINVAL);
                if (c.id == V4L2_CID_EXPOSURE_AUTO && c.value != V4L2_EXPOSURE_MANUAL &&
                    c.value != V4L2_EXPOSURE_APERTURE_PRIORITY)
                    return fail(EINVAL);
                controls[c.id] = std::clamp(c.value, 0, 2047);
                return 0;
            }
            default:
                return fail(ENOTTY);
        }
    }

    void* mmap(size_t length, int fd, int64_t offset) override {
        const size_t i = size_t(offset) / kPage;
        if (fd != kFd || i >= buffers_.size() || length != buffers_[i].size()) {
            errno = EINVAL;
            return MAP_FAILED;
        }
        return buffers_[i].data();
    }
    int munmap(void*, size_t) override {
        ++unmapped;
        return 0;
    }
    int poll(int fd, int) override {
        if (fd != kFd) return fail(EBADF);
        if (!script.empty() && script.front() == Event::Timeout) {
            script.pop_front();
            return 0;
        }
        return 1;  // unplugged: readable (the error comes from DQBUF), as a UVC node does
    }
    void close(int fd) override {
        if (fd == kFd) ++closed;
    }

    // The picture of frame `n`: a smooth gradient and a white square that moves 24 pixels per
    // frame, as the fake camera films it.
    static cv::Mat picture(uint32_t width, uint32_t height, uint32_t n) {
        cv::Mat bgr(int(height), int(width), CV_8UC3);
        for (int y = 0; y < bgr.rows; ++y)
            for (int x = 0; x < bgr.cols; ++x)
                bgr.at<cv::Vec3b>(y, x) =
                    cv::Vec3b(uchar(40 + 160 * x / bgr.cols), uchar(40 + 160 * y / bgr.rows), 90);
        const int side = int(height) / 6;
        cv::rectangle(bgr, cv::Rect(int(8 + 24 * (n % 10)), side, side, side),
                      cv::Scalar(255, 255, 255), cv::FILLED);
        return bgr;
    }

private:
    static constexpr int kFd = 42;
    static constexpr size_t kPage = 4096;
    std::vector<std::vector<uint8_t>> buffers_;
    std::deque<uint32_t> queued_;
    bool streaming_ = false, unplugged_ = false;
    uint32_t sequence_ = 0;

    static int fail(int e) {
        errno = e;
        return -1;
    }

    int dequeue(v4l2_buffer& b) {
        if (!streaming_) return fail(EINVAL);
        if (eagainForever) return fail(EAGAIN);
        Event e = Event::Frame;
        if (!script.empty()) {
            e = script.front();
            if (e != Event::Unplugged) script.pop_front();
        }
        if (e == Event::Unplugged) {
            unplugged_ = true;
            return fail(ENODEV);
        }
        if (e == Event::EagainAfterWake) return fail(EAGAIN);
        if (queued_.empty()) {
            ++dequeuedWithNothingQueued;
            return fail(EAGAIN);
        }
        if (e == Event::SequenceGap) sequence_ += 2;
        const uint32_t i = queued_.front();
        queued_.pop_front();
        std::vector<uint8_t>& buf = buffers_[i];
        size_t used = 0;
        const cv::Mat bgr = picture(width, height, sequence_);
        if (fourcc == V4L2_PIX_FMT_MJPEG) {
            std::vector<uint8_t> jpeg;
            cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95});
            used = std::min(jpeg.size(), buf.size());
            std::memcpy(buf.data(), jpeg.data(), used);
        } else {
            // YUYV from the picture's luma and a neutral chroma.
            cv::Mat grey;
            cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
            for (uint32_t p = 0; p < width * height; ++p) {
                buf[2 * p] = uchar(16 + grey.data[p] * 219 / 255);
                buf[2 * p + 1] = 128;
            }
            used = 2 * width * height;
        }
        b = v4l2_buffer{};
        b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        b.memory = V4L2_MEMORY_MMAP;
        b.index = i;
        b.bytesused = uint32_t(used);
        b.sequence = sequence_++;
        const double now = steadySeconds();
        b.timestamp.tv_sec = long(now);
        b.timestamp.tv_usec = long((now - double(long(now))) * 1e6);
        b.flags = monotonicClock ? V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC : V4L2_BUF_FLAG_TIMESTAMP_COPY;
        if (e == Event::ErrorFlagged) b.flags |= V4L2_BUF_FLAG_ERROR;
        return 0;
    }
};

CaptureRequest vga(CaptureRequest::Format format = CaptureRequest::Format::Mjpeg) {
    CaptureRequest r;
    r.width = 640;
    r.height = 480;
    r.fps = 30;
    r.format = format;
    return r;
}

std::unique_ptr<V4l2Camera> camera(const std::shared_ptr<FakeDriver>& driver,
                                   const CaptureRequest& request = vga()) {
    return std::make_unique<V4l2Camera>(std::make_unique<V4l2Device>("/dev/fake0", driver),
                                        request);
}

// A device on the fake driver, streaming MJPEG 640x480 at 30 frames/s.
std::unique_ptr<V4l2Device> streamingVga(const std::shared_ptr<FakeDriver>& driver) {
    auto dev = std::make_unique<V4l2Device>("/dev/fake0", driver);
    dev->configure({PixelFormat::Mjpeg, 640, 480, 30});
    dev->start();
    return dev;
}

// Many more frames than buffers: each buffer goes back to the driver before the next dequeue,
// every frame decodes to the picture the camera filmed, and the driver's monotonic clock stamps
// it. The pictures are compared with a tolerance for the JPEG (measured: 50.5-50.8 dB); a
// wrong frame (the next one's picture) falls far below it (19 dB).
TEST(V4l2Device, StreamsEveryBufferBackToTheDriver) {
    auto driver = std::make_shared<FakeDriver>();
    CaptureRequest small = vga();
    small.width = 320;
    small.height = 240;
    auto cam = camera(driver, small);
    EXPECT_EQ(cam->mode().width, 320);
    EXPECT_TRUE(cam->modeNote().empty()) << cam->modeNote();
    cv::Mat bgr;
    double lastT = -1;
    for (uint32_t n = 0; n < 12; ++n) {
        ASSERT_TRUE(cam->read(bgr)) << "frame " << n;
        ASSERT_EQ(bgr.size(), cv::Size(320, 240));
        const double same = psnr(bgr, FakeDriver::picture(320, 240, n), 255);
        const double other = psnr(bgr, FakeDriver::picture(320, 240, n + 1), 255);
        std::printf("frame %u: %.1f dB, the next frame's picture %.1f dB\n", n, same, other);
        EXPECT_GT(same, 40.0) << "frame " << n;
        EXPECT_LT(other, 30.0) << "frame " << n;
        ASSERT_TRUE(cam->lastTimestamp());
        EXPECT_GT(*cam->lastTimestamp(), lastT);
        lastT = *cam->lastTimestamp();
    }
    EXPECT_EQ(driver->dequeuedWithNothingQueued, 0);
    EXPECT_EQ(cam->droppedFrames(), 0);
    cam.reset();
    EXPECT_EQ(driver->closed, 1);
    EXPECT_EQ(driver->unmapped, 4);  // every mapped buffer released
}

// poll() can wake without a buffer (EAGAIN on DQBUF): the device waits again.
TEST(V4l2Device, EagainAfterAWakeIsWaitedOut) {
    auto driver = std::make_shared<FakeDriver>();
    driver->script = {FakeDriver::Event::EagainAfterWake, FakeDriver::Event::EagainAfterWake,
                      FakeDriver::Event::Frame};
    const auto dev = streamingVga(driver);
    RawFrame raw;
    ASSERT_TRUE(dev->dequeue(raw, 500));
    EXPECT_EQ(raw.sequence, 0);
    EXPECT_GT(raw.size, 0u);
    EXPECT_TRUE(driver->script.empty());
}

// A driver that keeps waking poll() but never gives a buffer must not hold the caller past the
// timeout (poll with 0 ms left returns at once, so a loop without a deadline check spins).
TEST(V4l2Device, EndlessEagainEndsAtTheTimeout) {
    auto driver = std::make_shared<FakeDriver>();
    const auto dev = streamingVga(driver);
    driver->eagainForever = true;
    RawFrame raw;
    const double t0 = steadySeconds();
    try {
        dev->dequeue(raw, 50);
        ADD_FAILURE() << "a frame out of a driver that has none";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("no frame for 50 ms"), std::string::npos) << e.what();
    }
    EXPECT_LT(steadySeconds() - t0, 2.0);
}

TEST(V4l2Device, PollTimeoutSaysStalled) {
    auto driver = std::make_shared<FakeDriver>();
    driver->script = {FakeDriver::Event::Timeout};
    auto cam = camera(driver);
    cv::Mat bgr;
    try {
        cam->read(bgr);
        ADD_FAILURE() << "a frame after a timeout";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("camera unplugged or stalled"), std::string::npos)
            << e.what();
    }
}

// ENODEV mid-stream: frames until then, then an error that names the device and the cause
// (what LatestFrameCapture reports as "camera lost" and reconnects from: CameraDouble_test).
TEST(V4l2Device, UnpluggedMidStreamSaysSo) {
    auto driver = std::make_shared<FakeDriver>();
    driver->script = {FakeDriver::Event::Frame, FakeDriver::Event::Frame,
                      FakeDriver::Event::Unplugged};
    auto cam = camera(driver);
    cv::Mat bgr;
    EXPECT_TRUE(cam->read(bgr));
    EXPECT_TRUE(cam->read(bgr));
    try {
        cam->read(bgr);
        ADD_FAILURE() << "a frame from an unplugged camera";
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("/dev/fake0 (Fake Webcam)"), std::string::npos) << what;
        EXPECT_NE(what.find("unplugged"), std::string::npos) << what;
        EXPECT_NE(what.find(std::strerror(ENODEV)), std::string::npos) << what;
    }
    cam.reset();  // stopping an unplugged camera does not throw out of the destructor
    EXPECT_EQ(driver->closed, 1);
}

// A size and rate the driver adjusts: used as given, and said.
TEST(V4l2Device, ModeTheDriverAdjustsIsUsedAndSaid) {
    auto driver = std::make_shared<FakeDriver>();
    driver->forcedWidth = 320;
    driver->forcedHeight = 240;
    driver->forcedFps = 15;
    auto cam = camera(driver);
    EXPECT_EQ(cam->mode().width, 320);
    EXPECT_EQ(cam->mode().height, 240);
    EXPECT_DOUBLE_EQ(cam->mode().fps, 15.0);
    EXPECT_NE(cam->modeNote().find("the driver gives MJPEG 320x240 at 15.00 fps"),
              std::string::npos)
        << cam->modeNote();
    cv::Mat bgr;
    ASSERT_TRUE(cam->read(bgr));
    EXPECT_EQ(bgr.size(), cv::Size(320, 240));
}

// The modes as the driver enumerates them; YUYV frames with the driver's stride.
TEST(V4l2Device, EnumeratesModesAndStreamsYuyv) {
    auto driver = std::make_shared<FakeDriver>();
    V4l2Device dev("/dev/fake0", driver);
    const std::vector<CaptureMode> modes = dev.modes();
    ASSERT_EQ(modes.size(), 4u);
    EXPECT_EQ(modes[0].format, PixelFormat::Mjpeg);
    EXPECT_DOUBLE_EQ(modes[1].fps, 15.0);
    EXPECT_EQ(modes[3].format, PixelFormat::Yuyv);
    const CaptureMode got = dev.configure({PixelFormat::Yuyv, 640, 480, 10});
    EXPECT_EQ(got.format, PixelFormat::Yuyv);
    dev.start();
    RawFrame raw;
    ASSERT_TRUE(dev.dequeue(raw, 500));
    EXPECT_EQ(raw.bytesPerLine, 1280);
    EXPECT_EQ(raw.size, size_t(640 * 480 * 2));
    cv::Mat bgr;
    ASSERT_TRUE(convertToBgr(raw, bgr));
    EXPECT_EQ(bgr.size(), cv::Size(640, 480));
}

// A buffer the driver flags bad is skipped and counted; a sequence gap counts the frames the
// driver dropped; a driver clock that is not CLOCK_MONOTONIC is not used as one.
TEST(V4l2Device, BadBuffersGapsAndForeignClocks) {
    auto driver = std::make_shared<FakeDriver>();
    driver->script = {FakeDriver::Event::Frame, FakeDriver::Event::ErrorFlagged,
                      FakeDriver::Event::SequenceGap};
    auto cam = camera(driver);
    cv::Mat bgr;
    ASSERT_TRUE(cam->read(bgr));
    ASSERT_TRUE(cam->read(bgr));  // the flagged frame is skipped, the next one returned
    EXPECT_EQ(cam->corruptFrames(), 1);
    EXPECT_EQ(cam->droppedFrames(), 2);

    auto foreign = std::make_shared<FakeDriver>();
    foreign->monotonicClock = false;
    const auto dev = streamingVga(foreign);
    RawFrame raw;
    ASSERT_TRUE(dev->dequeue(raw, 500));
    EXPECT_LT(raw.deviceSeconds, 0.0);
}

// A webcam's metadata node (no video capture) is refused with what to try, and closed.
TEST(V4l2Device, MetadataNodeIsRefused) {
    auto driver = std::make_shared<FakeDriver>();
    driver->capabilities = V4L2_CAP_META_CAPTURE | V4L2_CAP_STREAMING;
    try {
        V4l2Device dev("/dev/fake1", driver);
        ADD_FAILURE() << "a metadata node opened as a camera";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("try the other /dev/videoN"), std::string::npos)
            << e.what();
    }
    EXPECT_EQ(driver->opened, 1);
    EXPECT_EQ(driver->closed, 1);
}

// Exposure through UVC's menu: manual for "off", aperture priority for "on" (UVC webcams offer no
// plain auto); an absolute exposure is set and read back.
TEST(V4l2Device, ExposureControlsThroughTheUvcMenu) {
    auto driver = std::make_shared<FakeDriver>();
    V4l2Device dev("/dev/fake0", driver);
    const std::vector<CameraControl> controls = dev.controls();
    ASSERT_EQ(controls.size(), 2u);
    EXPECT_EQ(controls[0].id, CameraControlId::AutoExposure);
    EXPECT_EQ(controls[0].value, 1);
    EXPECT_EQ(dev.setControl(CameraControlId::AutoExposure, 0), 0);
    EXPECT_EQ(driver->controls[V4L2_CID_EXPOSURE_AUTO], V4L2_EXPOSURE_MANUAL);
    EXPECT_EQ(dev.setControl(CameraControlId::Exposure, 300), 300);
    EXPECT_EQ(dev.setControl(CameraControlId::AutoExposure, 1), 1);
    EXPECT_EQ(driver->controls[V4L2_CID_EXPOSURE_AUTO], V4L2_EXPOSURE_APERTURE_PRIORITY);
    EXPECT_EQ(dev.setControl(CameraControlId::Gain, 10), std::nullopt);  // not offered
}

}  // namespace
}  // namespace mirage::test
