#pragma once
// The calls V4l2Device makes into the kernel: through libv4l2 for a real camera (the default),
// or a fake driver in tests, so that the device's streaming, timing and error handling run
// without a webcam exactly as they run with one (EAGAIN after a wake-up, ENODEV mid-stream, a
// mode the driver adjusts, buffers flagged bad).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include <linux/videodev2.h>

namespace mirage {

class V4l2Kernel {
public:
    virtual ~V4l2Kernel() = default;
    // Opens the V4L2 node `path` and fills `cap` (VIDIOC_QUERYCAP); returns the descriptor for
    // the other calls. Throws mirage::Error that says what to check (no such node, not a device
    // file, permissions, busy, not V4L2).
    virtual int open(const std::string& path, v4l2_capability& cap) = 0;
    // As ioctl(2) (EINTR already retried): 0, or -1 with errno set.
    virtual int ioctl(int fd, unsigned long request, void* arg) = 0;
    // As mmap(2) of a streaming buffer (read/write, shared): MAP_FAILED with errno on failure.
    virtual void* mmap(size_t length, int fd, int64_t offset) = 0;
    virtual int munmap(void* start, size_t length) = 0;
    // As poll(2) for POLLIN on `fd` (EINTR already retried): > 0 ready, 0 timed out, -1 errno.
    virtual int poll(int fd, int timeoutMs) = 0;
    virtual void close(int fd) = 0;
};

// The real kernel, through libv4l2 (which converts formats and works around driver quirks).
std::shared_ptr<V4l2Kernel> libv4l2Kernel();

}  // namespace mirage
