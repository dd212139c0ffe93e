#pragma once
// Move-only RAII owners of Embree 3 handles. The device installs an error callback that turns
// Embree errors into mirage::Error (with Embree's message), so a failed rtcNewDevice, a bad build
// or an out-of-memory never passes silently.
#include <string>

#include <embree3/rtcore.h>

namespace mirage::raytrace {

class EmbreeDevice {
public:
    // `config` is Embree's device string (e.g. "threads=2"); empty = Embree's defaults.
    explicit EmbreeDevice(const std::string& config = "");
    ~EmbreeDevice();
    EmbreeDevice(EmbreeDevice&& o) noexcept : device_(o.device_) { o.device_ = nullptr; }
    EmbreeDevice& operator=(EmbreeDevice&& o) noexcept;
    EmbreeDevice(const EmbreeDevice&) = delete;
    EmbreeDevice& operator=(const EmbreeDevice&) = delete;

    RTCDevice get() const { return device_; }
    // Throws mirage::Error if Embree recorded an error since the last call (rtcGetDeviceError).
    void throwIfError(const char* what) const;

private:
    RTCDevice device_ = nullptr;
};

class EmbreeScene {
public:
    EmbreeScene() = default;
    explicit EmbreeScene(const EmbreeDevice& device);
    ~EmbreeScene();
    EmbreeScene(EmbreeScene&& o) noexcept : scene_(o.scene_) { o.scene_ = nullptr; }
    EmbreeScene& operator=(EmbreeScene&& o) noexcept;
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    RTCScene get() const { return scene_; }
    explicit operator bool() const { return scene_ != nullptr; }

private:
    RTCScene scene_ = nullptr;
};

}  // namespace mirage::raytrace
