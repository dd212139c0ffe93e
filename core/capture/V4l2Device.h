#pragma once
// A V4L2 camera (/dev/videoN) through libv4l2: native format enumeration, memory-mapped
// streaming with a few buffers, driver timestamps. Linux only.
#include <memory>
#include <string>

#include "core/capture/CaptureDevice.h"
#include "core/capture/V4l2Kernel.h"

namespace mirage {

class V4l2Device final : public CaptureDevice {
public:
    // Opens the device; throws mirage::Error naming the device and what to check (is a camera
    // plugged in? permissions: the `video` group?) if it is missing or not a capture device.
    // `kernel`: the calls into the kernel (a fake driver in tests).
    explicit V4l2Device(const std::string& devicePath,
                        std::shared_ptr<V4l2Kernel> kernel = libv4l2Kernel());
    ~V4l2Device() override;
    V4l2Device(const V4l2Device&) = delete;
    V4l2Device& operator=(const V4l2Device&) = delete;

    std::string name() const override;
    std::string card() const;  // the driver's name of the camera model ("HD Webcam C270")
    std::vector<CaptureMode> modes() override;
    CaptureMode configure(const CaptureMode& mode) override;
    void start() override;
    bool dequeue(RawFrame& frame, int timeoutMs) override;
    void stop() override;
    std::vector<CameraControl> controls() override;
    std::optional<int64_t> setControl(CameraControlId id, int64_t value) override;

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

// "/dev/video0" for "0", anything else unchanged.
std::string v4l2DevicePath(const std::string& deviceOrIndex);

}  // namespace mirage
