#pragma once
// Device-independent capture logic: choosing a mode, converting frames to BGR, timestamps.
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/capture/CaptureDevice.h"

namespace mirage {

struct CaptureRequest {
    int width = 1280, height = 720;  // wanted size, pixels
    double fps = 30;                 // wanted frame rate
    // Auto: YUYV (uncompressed, no JPEG artefacts) when the device gives it at the wanted size
    // and rate, else MJPEG (USB 2 cameras usually reach 30 fps at 720p only in MJPEG).
    enum class Format { Auto, Mjpeg, Yuyv } format = Format::Auto;
};

// The best mode for a request: the wanted size if offered (else the nearest in area with the
// same aspect ratio preferred), then the wanted rate (the nearest at or above it, else the
// fastest), then the format preference. nullopt if `modes` is empty or the forced format is
// not offered at all.
std::optional<CaptureMode> chooseCaptureMode(const std::vector<CaptureMode>& modes,
                                             const CaptureRequest& request);

// Converts a raw frame to 8-bit BGR (sRGB-encoded). YUYV: BT.601 limited range (OpenCV's
// conversion), honouring the row stride. MJPEG: decoded by libjpeg. Returns false (and leaves
// `bgr` empty) for a corrupt or short frame — cameras do deliver those; callers drop them.
bool convertToBgr(const RawFrame& frame, cv::Mat& bgr);

// BGR -> YUYV (BT.601 limited range, chroma averaged over each pixel pair): the inverse of
// convertToBgr, used by VideoFileCaptureDevice to pose as a YUYV camera. Width must be even.
std::vector<uint8_t> bgrToYuyv(const cv::Mat& bgr);

// Turns device timestamps into session time (seconds). Uses the driver's monotonic timestamp
// when it has one and it increases; otherwise the host's steady clock at dequeue time (and
// stays on it, so one recording never mixes clocks). Counts frames the driver dropped from
// gaps in its sequence numbers.
class FrameClock {
public:
    // `hostSeconds` is the steady-clock time when the frame was dequeued.
    double stamp(const RawFrame& frame, double hostSeconds);
    int droppedFrames() const { return dropped_; }
    bool usingDeviceClock() const { return useDevice_; }

private:
    bool first_ = true;
    bool useDevice_ = true;
    double last_ = 0;
    int64_t lastSequence_ = -1;
    int dropped_ = 0;
};

double steadySeconds();  // std::chrono::steady_clock (CLOCK_MONOTONIC on Linux), seconds

}  // namespace mirage
