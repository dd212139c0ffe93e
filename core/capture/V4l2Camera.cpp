#include "core/capture/V4l2Camera.h"

#include <cmath>

#include <spdlog/spdlog.h>

#include "core/Error.h"
#include "core/capture/V4l2Device.h"

namespace mirage {

V4l2Camera::V4l2Camera(const std::string& device, const CaptureRequest& request)
    : V4l2Camera(std::make_unique<V4l2Device>(device), request) {}

V4l2Camera::V4l2Camera(std::unique_ptr<CaptureDevice> device, const CaptureRequest& request)
    : device_(std::move(device)) {
    MR_CHECK(device_ != nullptr, "V4l2Camera needs a device");
    const std::vector<CaptureMode> modes = device_->modes();
    const auto chosen = chooseCaptureMode(modes, request);
    if (!chosen) {
        std::string offered;
        for (const auto& m : modes)
            offered += std::string(offered.empty() ? "" : ", ") + pixelFormatName(m.format) + " " +
                       std::to_string(m.width) + "x" + std::to_string(m.height) + "@" +
                       std::to_string(int(m.fps));
        throw Error(device_->name() +
                    ": no usable capture mode (mirage reads MJPEG and YUYV; "
                    "the device offers: " +
                    (offered.empty() ? "nothing" : offered) + ")");
    }
    mode_ = device_->configure(*chosen);
    if (mode_.format != chosen->format || mode_.width != chosen->width ||
        mode_.height != chosen->height || std::abs(mode_.fps - chosen->fps) > 0.01) {
        modeNote_ =
            fmt::format("asked {} {}x{} at {:.2f} fps, the driver gives {} {}x{} at {:.2f} fps",
                        pixelFormatName(chosen->format), chosen->width, chosen->height, chosen->fps,
                        pixelFormatName(mode_.format), mode_.width, mode_.height, mode_.fps);
        spdlog::warn("camera {}: {}; using what it gives", device_->name(), modeNote_);
    }
    spdlog::info("camera {}: {} {}x{} at {:.2f} fps", device_->name(),
                 pixelFormatName(mode_.format), mode_.width, mode_.height, mode_.fps);
    device_->start();
}

V4l2Camera::~V4l2Camera() {
    try {
        device_->stop();
    } catch (...) {
    }
}

ExposureLockReport V4l2Camera::lockExposure(const ExposureSettings& settings) {
    ExposureLockReport r = mirage::lockExposure(*device_, settings);
    for (const auto& n : r.notes) spdlog::info("camera {}: {}", device_->name(), n);
    for (const auto& w : r.warnings) spdlog::warn("camera {}: {}", device_->name(), w);
    return r;
}

bool V4l2Camera::read(cv::Mat& bgr) {
    // A few corrupt frames in a row are normal right after start-up; many mean a broken stream.
    for (int attempt = 0; attempt < 30; ++attempt) {
        RawFrame raw;
        if (!device_->dequeue(raw, timeoutMs)) return false;
        const double host = steadySeconds();
        // Stamped even when it does not decode: its sequence number is a frame the driver
        // delivered (counted as corrupt), not one it dropped.
        const double t = clock_.stamp(raw, host);
        dropped_ = clock_.droppedFrames();
        if (!convertToBgr(raw, bgr)) {
            ++corrupt_;
            continue;
        }
        last_ = t;
        return true;
    }
    throw Error(device_->name() +
                ": 30 corrupt frames in a row; check the cable/USB bandwidth "
                "or ask for a smaller size");
}

}  // namespace mirage
