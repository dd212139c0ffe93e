#include "core/capture/V4l2Device.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

#include <libv4l2.h>

#include "core/Error.h"
#include "core/capture/CaptureFormat.h"

namespace mirage {

namespace {

constexpr int kBufferCount = 4;  // enough to absorb a slow frame without the driver dropping

std::string errnoText(int e) {
    return std::strerror(e);
}

class Libv4l2Kernel final : public V4l2Kernel {
public:
    int open(const std::string& path, v4l2_capability& cap) override {
        struct stat st {};
        if (::stat(path.c_str(), &st) != 0)
            throw Error("camera " + path +
                        " not found: is a camera plugged in? (`ls /dev/video*`; a recorded "
                        "session or video can stand in for a camera: `mirage live --camera "
                        "SESSION`)");
        if (!S_ISCHR(st.st_mode))
            throw Error("camera " + path + " is not a device file (expected /dev/videoN)");
        // Plain open + QUERYCAP first, so that a non-V4L2 file gets a clear error (and libv4l2
        // prints nothing); then libv4l2 wraps the descriptor.
        const int raw = ::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
        if (raw < 0) {
            const int e = errno;
            throw Error("cannot open camera " + path + ": " + errnoText(e) +
                        (e == EACCES  ? " (add your user to the `video` group)"
                         : e == EBUSY ? " (another program is using it)"
                                      : ""));
        }
        int r;
        do {
            r = ::ioctl(raw, VIDIOC_QUERYCAP, &cap);
        } while (r == -1 && errno == EINTR);
        if (r != 0) {
            const int e = errno;
            ::close(raw);
            throw Error(path + " is not a V4L2 device (" + errnoText(e) +
                        "); cameras are /dev/videoN");
        }
        const int fd = v4l2_fd_open(raw, 0);
        if (fd < 0) {
            const int e = errno;
            ::close(raw);
            throw Error("libv4l2 cannot use camera " + path + ": " + errnoText(e));
        }
        return fd;
    }
    int ioctl(int fd, unsigned long request, void* arg) override {
        int r;
        do {
            r = v4l2_ioctl(fd, request, arg);
        } while (r == -1 && errno == EINTR);
        return r;
    }
    void* mmap(size_t length, int fd, int64_t offset) override {
        return v4l2_mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, offset);
    }
    int munmap(void* start, size_t length) override { return v4l2_munmap(start, length); }
    int poll(int fd, int timeoutMs) override {
        pollfd p{fd, POLLIN, 0};
        int r;
        do {
            r = ::poll(&p, 1, timeoutMs);
        } while (r < 0 && errno == EINTR);
        return r;
    }
    void close(int fd) override { v4l2_close(fd); }
};

}  // namespace

std::shared_ptr<V4l2Kernel> libv4l2Kernel() {
    static const std::shared_ptr<V4l2Kernel> kernel = std::make_shared<Libv4l2Kernel>();
    return kernel;
}

std::string v4l2DevicePath(const std::string& d) {
    if (!d.empty() && std::all_of(d.begin(), d.end(), [](char c) { return c >= '0' && c <= '9'; }))
        return "/dev/video" + d;
    return d;
}

struct V4l2Device::Impl {
    std::shared_ptr<V4l2Kernel> kernel;
    std::string path, card;
    int fd = -1;
    struct Buffer {
        void* start = MAP_FAILED;
        size_t length = 0;
    };
    std::vector<Buffer> buffers;
    bool streaming = false;
    int queuedIndex = -1;  // buffer handed out by the last dequeue, requeued on the next
    CaptureMode mode;
    int bytesPerLine = 0;

    [[noreturn]] void fail(const std::string& what, int err) const {
        throw Error(path + " (" + card + "): " + what + ": " + errnoText(err));
    }

    void releaseBuffers() {
        for (auto& b : buffers)
            if (b.start != MAP_FAILED) kernel->munmap(b.start, b.length);
        buffers.clear();
        if (fd >= 0) {
            v4l2_requestbuffers req{};
            req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
            req.memory = V4L2_MEMORY_MMAP;
            req.count = 0;
            kernel->ioctl(fd, VIDIOC_REQBUFS, &req);
        }
    }
};

V4l2Device::V4l2Device(const std::string& deviceOrIndex, std::shared_ptr<V4l2Kernel> kernel)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    MR_CHECK(kernel != nullptr, "V4l2Device needs a kernel");
    m.kernel = std::move(kernel);
    m.path = v4l2DevicePath(deviceOrIndex);
    v4l2_capability cap{};
    m.fd = m.kernel->open(m.path, cap);
    m.card = reinterpret_cast<const char*>(cap.card);
    const uint32_t caps =
        (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
    if (!(caps & V4L2_CAP_VIDEO_CAPTURE) || !(caps & V4L2_CAP_STREAMING)) {
        m.kernel->close(m.fd);
        m.fd = -1;
        throw Error(m.path + " (" + m.card +
                    ") cannot stream video capture (it may be the metadata node of a webcam; "
                    "try the other /dev/videoN of the same camera)");
    }
}

V4l2Device::~V4l2Device() {
    try {
        stop();
    } catch (...) {
    }
    if (impl_->fd >= 0) impl_->kernel->close(impl_->fd);
}

std::string V4l2Device::name() const {
    return impl_->path + " (" + impl_->card + ")";
}

std::string V4l2Device::card() const {
    return impl_->card;
}

std::vector<CaptureMode> V4l2Device::modes() {
    Impl& m = *impl_;
    std::vector<CaptureMode> out;
    for (uint32_t fi = 0;; ++fi) {
        v4l2_fmtdesc fmt{};
        fmt.index = fi;
        fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        if (m.kernel->ioctl(m.fd, VIDIOC_ENUM_FMT, &fmt) != 0) break;
        // libv4l2 adds converted formats (flag EMULATED); mirage converts itself.
        if (fmt.flags & V4L2_FMT_FLAG_EMULATED) continue;
        if (fmt.pixelformat != V4L2_PIX_FMT_MJPEG && fmt.pixelformat != V4L2_PIX_FMT_YUYV) continue;
        const PixelFormat pf =
            fmt.pixelformat == V4L2_PIX_FMT_MJPEG ? PixelFormat::Mjpeg : PixelFormat::Yuyv;
        for (uint32_t si = 0;; ++si) {
            v4l2_frmsizeenum size{};
            size.index = si;
            size.pixel_format = fmt.pixelformat;
            if (m.kernel->ioctl(m.fd, VIDIOC_ENUM_FRAMESIZES, &size) != 0) break;
            // Stepwise/continuous sizes (rare on webcams): offer the largest.
            const uint32_t w = size.type == V4L2_FRMSIZE_TYPE_DISCRETE ? size.discrete.width
                                                                       : size.stepwise.max_width;
            const uint32_t h = size.type == V4L2_FRMSIZE_TYPE_DISCRETE ? size.discrete.height
                                                                       : size.stepwise.max_height;
            bool any = false;
            for (uint32_t ii = 0;; ++ii) {
                v4l2_frmivalenum iv{};
                iv.index = ii;
                iv.pixel_format = fmt.pixelformat;
                iv.width = w;
                iv.height = h;
                if (m.kernel->ioctl(m.fd, VIDIOC_ENUM_FRAMEINTERVALS, &iv) != 0) break;
                const v4l2_fract f =
                    iv.type == V4L2_FRMIVAL_TYPE_DISCRETE ? iv.discrete : iv.stepwise.min;
                if (f.numerator > 0) {
                    out.push_back({pf, int(w), int(h), double(f.denominator) / f.numerator});
                    any = true;
                }
                if (iv.type != V4L2_FRMIVAL_TYPE_DISCRETE) break;
            }
            if (!any) out.push_back({pf, int(w), int(h), 30.0});  // driver lists no rates
            if (size.type != V4L2_FRMSIZE_TYPE_DISCRETE) break;
        }
    }
    return out;
}

CaptureMode V4l2Device::configure(const CaptureMode& mode) {
    Impl& m = *impl_;
    if (m.streaming) stop();
    v4l2_format fmt{};
    fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    fmt.fmt.pix.width = uint32_t(mode.width);
    fmt.fmt.pix.height = uint32_t(mode.height);
    fmt.fmt.pix.pixelformat =
        mode.format == PixelFormat::Mjpeg ? V4L2_PIX_FMT_MJPEG : V4L2_PIX_FMT_YUYV;
    fmt.fmt.pix.field = V4L2_FIELD_NONE;
    if (m.kernel->ioctl(m.fd, VIDIOC_S_FMT, &fmt) != 0)
        m.fail("cannot set the capture format", errno);
    if (fmt.fmt.pix.pixelformat != V4L2_PIX_FMT_MJPEG &&
        fmt.fmt.pix.pixelformat != V4L2_PIX_FMT_YUYV)
        throw Error(name() + ": the driver refused " + pixelFormatName(mode.format));
    CaptureMode got = mode;
    got.width = int(fmt.fmt.pix.width);
    got.height = int(fmt.fmt.pix.height);
    got.format =
        fmt.fmt.pix.pixelformat == V4L2_PIX_FMT_MJPEG ? PixelFormat::Mjpeg : PixelFormat::Yuyv;
    m.bytesPerLine = got.format == PixelFormat::Yuyv
                         ? std::max(int(fmt.fmt.pix.bytesperline), 2 * got.width)
                         : 0;

    v4l2_streamparm parm{};
    parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    parm.parm.capture.timeperframe.numerator = 1000;
    parm.parm.capture.timeperframe.denominator = uint32_t(std::lround(mode.fps * 1000));
    if (m.kernel->ioctl(m.fd, VIDIOC_S_PARM, &parm) == 0 &&
        parm.parm.capture.timeperframe.numerator > 0)
        got.fps = double(parm.parm.capture.timeperframe.denominator) /
                  parm.parm.capture.timeperframe.numerator;
    m.mode = got;
    return got;
}

void V4l2Device::start() {
    Impl& m = *impl_;
    if (m.streaming) return;
    v4l2_requestbuffers req{};
    req.count = kBufferCount;
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    if (m.kernel->ioctl(m.fd, VIDIOC_REQBUFS, &req) != 0)
        m.fail("cannot allocate streaming buffers", errno);
    if (req.count < 2) throw Error(name() + ": the driver gave fewer than 2 buffers");
    for (uint32_t i = 0; i < req.count; ++i) {
        v4l2_buffer buf{};
        buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        buf.memory = V4L2_MEMORY_MMAP;
        buf.index = i;
        if (m.kernel->ioctl(m.fd, VIDIOC_QUERYBUF, &buf) != 0) m.fail("cannot query buffer", errno);
        Impl::Buffer b;
        b.length = buf.length;
        b.start = m.kernel->mmap(buf.length, m.fd, buf.m.offset);
        if (b.start == MAP_FAILED) {
            const int e = errno;
            m.releaseBuffers();
            m.fail("cannot map buffer", e);
        }
        m.buffers.push_back(b);
        if (m.kernel->ioctl(m.fd, VIDIOC_QBUF, &buf) != 0) {
            const int e = errno;
            m.releaseBuffers();
            m.fail("cannot queue buffer", e);
        }
    }
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (m.kernel->ioctl(m.fd, VIDIOC_STREAMON, &type) != 0) {
        const int e = errno;
        m.releaseBuffers();
        m.fail("cannot start streaming", e);
    }
    m.streaming = true;
    m.queuedIndex = -1;
}

bool V4l2Device::dequeue(RawFrame& frame, int timeoutMs) {
    Impl& m = *impl_;
    if (!m.streaming) throw Error(name() + ": dequeue before start()");
    // Give the previous frame's buffer back to the driver first.
    if (m.queuedIndex >= 0) {
        v4l2_buffer buf{};
        buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        buf.memory = V4L2_MEMORY_MMAP;
        buf.index = uint32_t(m.queuedIndex);
        m.queuedIndex = -1;
        if (m.kernel->ioctl(m.fd, VIDIOC_QBUF, &buf) != 0) m.fail("cannot requeue buffer", errno);
    }
    // poll() can wake without a buffer being ready (EAGAIN on DQBUF): wait again until the
    // deadline.
    const double deadline = steadySeconds() + timeoutMs / 1000.0;
    v4l2_buffer buf{};
    for (;;) {
        const int leftMs = std::max(0, int((deadline - steadySeconds()) * 1000.0));
        const int r = m.kernel->poll(m.fd, leftMs);
        if (r < 0) m.fail("waiting for a frame failed", errno);
        const auto stalled = [&] {
            return Error(name() + ": no frame for " + std::to_string(timeoutMs) +
                         " ms (camera unplugged or stalled?)");
        };
        if (r == 0) throw stalled();
        buf = v4l2_buffer{};
        buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        buf.memory = V4L2_MEMORY_MMAP;
        if (m.kernel->ioctl(m.fd, VIDIOC_DQBUF, &buf) == 0) break;
        if (errno != EAGAIN) m.fail("cannot dequeue a frame (camera unplugged?)", errno);
        // A driver that keeps waking poll() without a buffer must not hold the caller past
        // the deadline (poll with 0 ms left returns at once).
        if (steadySeconds() >= deadline) throw stalled();
    }
    if (buf.index >= m.buffers.size()) throw Error(name() + ": driver returned an unknown buffer");
    m.queuedIndex = int(buf.index);
    frame.format = m.mode.format;
    frame.width = m.mode.width;
    frame.height = m.mode.height;
    frame.bytesPerLine = m.bytesPerLine;
    frame.bytes = static_cast<const uint8_t*>(m.buffers.at(buf.index).start);
    frame.size = std::min<size_t>(buf.bytesused, m.buffers[buf.index].length);
    frame.sequence = buf.sequence;
    // Only a monotonic driver clock is comparable with the host's; others are ignored.
    const bool monotonic =
        (buf.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
    frame.deviceSeconds =
        monotonic ? double(buf.timestamp.tv_sec) + double(buf.timestamp.tv_usec) * 1e-6 : -1.0;
    if (buf.flags & V4L2_BUF_FLAG_ERROR) frame.size = 0;  // the driver says the data is bad
    return true;
}

void V4l2Device::stop() {
    Impl& m = *impl_;
    if (!m.streaming) return;
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    m.kernel->ioctl(m.fd, VIDIOC_STREAMOFF, &type);
    m.streaming = false;
    m.queuedIndex = -1;
    m.releaseBuffers();
}

namespace {

uint32_t v4l2ControlId(CameraControlId id) {
    switch (id) {
        case CameraControlId::AutoExposure:
            return V4L2_CID_EXPOSURE_AUTO;
        case CameraControlId::Exposure:
            return V4L2_CID_EXPOSURE_ABSOLUTE;
        case CameraControlId::AutoGain:
            return V4L2_CID_AUTOGAIN;
        case CameraControlId::Gain:
            return V4L2_CID_GAIN;
        case CameraControlId::AutoWhiteBalance:
            return V4L2_CID_AUTO_WHITE_BALANCE;
        case CameraControlId::WhiteBalance:
            return V4L2_CID_WHITE_BALANCE_TEMPERATURE;
    }
    return 0;
}

// V4L2_CID_EXPOSURE_AUTO is a menu (auto, manual, shutter priority, aperture priority; UVC
// webcams usually offer manual and aperture priority); mirage's control is on/off.
int64_t fromV4l2(CameraControlId id, int64_t v) {
    if (id == CameraControlId::AutoExposure) return v == V4L2_EXPOSURE_MANUAL ? 0 : 1;
    return v;
}

}  // namespace

std::vector<CameraControl> V4l2Device::controls() {
    Impl& m = *impl_;
    std::vector<CameraControl> out;
    for (CameraControlId id : {CameraControlId::AutoExposure, CameraControlId::Exposure,
                               CameraControlId::AutoGain, CameraControlId::Gain,
                               CameraControlId::AutoWhiteBalance, CameraControlId::WhiteBalance}) {
        v4l2_queryctrl q{};
        q.id = v4l2ControlId(id);
        if (m.kernel->ioctl(m.fd, VIDIOC_QUERYCTRL, &q) != 0 || (q.flags & V4L2_CTRL_FLAG_DISABLED))
            continue;
        v4l2_control c{};
        c.id = q.id;
        if (m.kernel->ioctl(m.fd, VIDIOC_G_CTRL, &c) != 0) continue;
        out.push_back({id, q.minimum, q.maximum, fromV4l2(id, c.value)});
    }
    return out;
}

std::optional<int64_t> V4l2Device::setControl(CameraControlId id, int64_t value) {
    Impl& m = *impl_;
    std::vector<int64_t> tries = {value};
    if (id == CameraControlId::AutoExposure)
        tries = value == 0
                    ? std::vector<int64_t>{V4L2_EXPOSURE_MANUAL}
                    : std::vector<int64_t>{V4L2_EXPOSURE_APERTURE_PRIORITY, V4L2_EXPOSURE_AUTO};
    for (int64_t v : tries) {
        v4l2_control c{};
        c.id = v4l2ControlId(id);
        c.value = int32_t(v);
        if (m.kernel->ioctl(m.fd, VIDIOC_S_CTRL, &c) != 0) continue;
        if (m.kernel->ioctl(m.fd, VIDIOC_G_CTRL, &c) != 0) return std::nullopt;
        return fromV4l2(id, c.value);
    }
    return std::nullopt;
}

}  // namespace mirage
