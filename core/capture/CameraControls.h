#pragma once
// Locking a camera's exposure, gain and white balance through its controls (docs/live.md,
// "Exposure"). The differential composite adds the virtual objects' change of light to the
// footage, scaled by alpha = camera image / rendered real light: if the camera re-exposes
// while the session runs, the footage's brightness changes under a fixed alpha and the virtual
// objects' shadows and light come out too dark or too bright. So a live session switches
// automatic exposure, gain and white balance off (keeping the values the camera had settled on,
// unless the user gives values) and warns when the camera does not allow it.
#include <optional>
#include <string>
#include <vector>

#include "core/capture/CaptureDevice.h"

namespace mirage {

struct ExposureSettings {
    std::optional<int64_t> exposure;       // device units (V4L2: 100 us); nullopt = keep current
    std::optional<int64_t> gain;           // device units; nullopt = keep current
    std::optional<int64_t> whiteBalanceK;  // kelvin; nullopt = keep current
};

struct ExposureLockReport {
    bool exposureLocked = false;        // automatic exposure is off (or the camera has none)
    bool whiteBalanceLocked = false;    // automatic white balance is off
    std::vector<std::string> notes;     // what was set, for the log and the HUD
    std::vector<std::string> warnings;  // what could not be done, and what to do about it
};

// Switches automatic exposure, gain and white balance off where the device offers the
// controls, and sets the given values (clamped by the device; the notes say what it holds).
ExposureLockReport lockExposure(CaptureDevice& device, const ExposureSettings& settings);

}  // namespace mirage
