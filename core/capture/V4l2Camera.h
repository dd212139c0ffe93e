#pragma once
// A live camera as a FrameSource: opens a CaptureDevice (a V4L2 webcam by default), picks the
// mode that best fits a request (chooseCaptureMode), streams, converts each frame to 8-bit BGR
// (sRGB-encoded) and stamps it with session time (FrameClock). Corrupt frames from the device
// are dropped and counted, not returned.
#include <atomic>
#include <memory>
#include <string>

#include "core/capture/CameraControls.h"
#include "core/capture/CaptureDevice.h"
#include "core/capture/CaptureFormat.h"
#include "core/session/Session.h"

namespace mirage {

class V4l2Camera final : public FrameSource {
public:
    // "/dev/video0" or "0". Throws mirage::Error if there is no such camera or no usable mode.
    V4l2Camera(const std::string& device, const CaptureRequest& request);
    // Any device (tests, VideoFileCaptureDevice). Takes ownership.
    V4l2Camera(std::unique_ptr<CaptureDevice> device, const CaptureRequest& request);
    ~V4l2Camera() override;

    bool read(cv::Mat& bgr) override;  // false only when a recorded source ends
    int frameCount() const override { return -1; }
    std::optional<double> lastTimestamp() const override { return last_; }

    const CaptureMode& mode() const { return mode_; }
    // Empty when the device gave the mode asked for; else "asked ..., the driver gives ...":
    // the camera is used in the mode it gives (logged as a warning).
    const std::string& modeNote() const { return modeNote_; }
    // Automatic exposure, gain and white balance off (core/capture/CameraControls.h).
    ExposureLockReport lockExposure(const ExposureSettings& settings);
    int64_t deviceDroppedFrames() const override { return dropped_.load(); }
    int droppedFrames() const { return clock_.droppedFrames(); }  // by the driver
    int corruptFrames() const { return corrupt_; }                // undecodable, skipped
    int timeoutMs = 2000;  // a camera that delivers nothing for this long is an error

private:
    std::unique_ptr<CaptureDevice> device_;
    CaptureMode mode_;
    FrameClock clock_;
    std::optional<double> last_;
    int corrupt_ = 0;
    std::string modeNote_;
    std::atomic<int64_t> dropped_{0};  // read by other threads (the live loop's counters)
};

}  // namespace mirage
