#include "render/raytrace/EmbreeDevice.h"

#include <utility>

#include "core/Error.h"
#include "core/Log.h"

namespace mirage::raytrace {
namespace {

const char* errorName(RTCError e) {
    switch (e) {
        case RTC_ERROR_NONE:
            return "none";
        case RTC_ERROR_UNKNOWN:
            return "unknown";
        case RTC_ERROR_INVALID_ARGUMENT:
            return "invalid argument";
        case RTC_ERROR_INVALID_OPERATION:
            return "invalid operation";
        case RTC_ERROR_OUT_OF_MEMORY:
            return "out of memory";
        case RTC_ERROR_UNSUPPORTED_CPU:
            return "unsupported CPU";
        case RTC_ERROR_CANCELLED:
            return "cancelled";
    }
    return "unrecognised";
}

// Embree calls this from whichever thread hit the error; we log it here and throwIfError()
// turns the sticky device error into an exception at the next API boundary.
void onEmbreeError(void*, RTCError code, const char* message) {
    spdlog::error("Embree error ({}): {}", errorName(code), message ? message : "");
}

}  // namespace

EmbreeDevice::EmbreeDevice(const std::string& config) {
    device_ = rtcNewDevice(config.empty() ? nullptr : config.c_str());
    if (!device_)
        throw Error("Embree: rtcNewDevice(\"" + config +
                    "\") failed: " + errorName(rtcGetDeviceError(nullptr)) +
                    " (is the CPU supported by the installed libembree3?)");
    rtcSetDeviceErrorFunction(device_, onEmbreeError, nullptr);
}

EmbreeDevice::~EmbreeDevice() {
    if (device_) rtcReleaseDevice(device_);
}

EmbreeDevice& EmbreeDevice::operator=(EmbreeDevice&& o) noexcept {
    if (this != &o) {
        if (device_) rtcReleaseDevice(device_);
        device_ = std::exchange(o.device_, nullptr);
    }
    return *this;
}

void EmbreeDevice::throwIfError(const char* what) const {
    RTCError e = rtcGetDeviceError(device_);
    if (e != RTC_ERROR_NONE)
        throw Error(std::string("Embree: ") + what + " failed: " + errorName(e));
}

EmbreeScene::EmbreeScene(const EmbreeDevice& device) {
    scene_ = rtcNewScene(device.get());
    device.throwIfError("rtcNewScene");
    MR_CHECK(scene_ != nullptr, "rtcNewScene returned null without an error");
}

EmbreeScene::~EmbreeScene() {
    if (scene_) rtcReleaseScene(scene_);
}

EmbreeScene& EmbreeScene::operator=(EmbreeScene&& o) noexcept {
    if (this != &o) {
        if (scene_) rtcReleaseScene(scene_);
        scene_ = std::exchange(o.scene_, nullptr);
    }
    return *this;
}

}  // namespace mirage::raytrace
