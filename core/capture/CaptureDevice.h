#pragma once
// The device side of live capture, behind an interface so that everything above it (format
// choice, pixel conversion, timestamps, recording) runs the same with a real V4L2 camera
// (V4l2Device) and with a recorded video posing as a camera (VideoFileCaptureDevice), which is
// how it is tested on machines without a webcam.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace mirage {

// Pixel formats mirage asks cameras for (V4L2 fourcc codes).
enum class PixelFormat : uint32_t {
    Mjpeg = 0x47504A4D,  // 'MJPG': a JPEG per frame (full-range BT.601 YCbCr inside)
    Yuyv = 0x56595559,   // 'YUYV': 4:2:2 packed Y0 U Y1 V, limited-range BT.601
};
const char* pixelFormatName(PixelFormat f);

// One mode a device offers: a format at a size and frame rate.
struct CaptureMode {
    PixelFormat format = PixelFormat::Mjpeg;
    int width = 0, height = 0;  // pixels
    double fps = 0;             // frames per second
};

// One frame as the device delivers it. `bytes` stays valid until the next dequeue().
struct RawFrame {
    PixelFormat format = PixelFormat::Mjpeg;
    int width = 0, height = 0;
    int bytesPerLine = 0;  // YUYV row stride in bytes (>= 2 * width); 0 for MJPEG
    const uint8_t* bytes = nullptr;
    size_t size = 0;            // bytes used
    double deviceSeconds = -1;  // driver timestamp (CLOCK_MONOTONIC, seconds); < 0 = none
    int64_t sequence = -1;      // driver frame counter (gaps = dropped frames); < 0 = none
};

// Image controls mirage sets (V4L2: V4L2_CID_EXPOSURE_AUTO, _EXPOSURE_ABSOLUTE, _AUTOGAIN,
// _GAIN, _AUTO_WHITE_BALANCE, _WHITE_BALANCE_TEMPERATURE).
enum class CameraControlId {
    AutoExposure,      // 1 = automatic, 0 = manual
    Exposure,          // exposure time, device units (V4L2: 100 us)
    AutoGain,          // 1 = automatic, 0 = manual
    Gain,              // device units
    AutoWhiteBalance,  // 1 = automatic, 0 = manual
    WhiteBalance,      // colour temperature, kelvin
};
const char* cameraControlName(CameraControlId id);

struct CameraControl {
    CameraControlId id = CameraControlId::Exposure;
    int64_t min = 0, max = 0, value = 0;  // range and current value, device units
};

class CaptureDevice {
public:
    virtual ~CaptureDevice() = default;
    virtual std::string name() const = 0;  // for messages: "/dev/video0 (HD Webcam)"
    // Modes the device offers natively (no emulated formats).
    virtual std::vector<CaptureMode> modes() = 0;
    // Sets a mode; returns what the device actually accepted (drivers may adjust fps).
    virtual CaptureMode configure(const CaptureMode& mode) = 0;
    virtual void start() = 0;
    // Waits up to timeoutMs for the next frame. false = the source has ended (recorded video);
    // throws mirage::Error on a device error or timeout (camera unplugged).
    virtual bool dequeue(RawFrame& frame, int timeoutMs) = 0;
    virtual void stop() = 0;
    // The controls of CameraControlId the device offers, with their current values.
    virtual std::vector<CameraControl> controls() { return {}; }
    // Sets a control; returns the value the device holds afterwards (drivers clamp or refuse),
    // nullopt when the device has no such control or refuses it outright.
    virtual std::optional<int64_t> setControl(CameraControlId, int64_t) { return std::nullopt; }
};

}  // namespace mirage
