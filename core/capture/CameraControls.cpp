#include "core/capture/CameraControls.h"

#include <map>

namespace mirage {

const char* cameraControlName(CameraControlId id) {
    switch (id) {
        case CameraControlId::AutoExposure:
            return "automatic exposure";
        case CameraControlId::Exposure:
            return "exposure";
        case CameraControlId::AutoGain:
            return "automatic gain";
        case CameraControlId::Gain:
            return "gain";
        case CameraControlId::AutoWhiteBalance:
            return "automatic white balance";
        case CameraControlId::WhiteBalance:
            return "white balance";
    }
    return "?";
}

namespace {

struct Locker {
    CaptureDevice& device;
    std::map<CameraControlId, CameraControl> offered;
    ExposureLockReport report;

    bool has(CameraControlId id) const { return offered.count(id) != 0; }

    // Switches an automatic control off; false (with a warning) when the device refuses.
    bool switchOff(CameraControlId autoId, const std::string& consequence) {
        const std::optional<int64_t> got = device.setControl(autoId, 0);
        if (got && *got == 0) return true;
        report.warnings.push_back(std::string(cameraControlName(autoId)) +
                                  " cannot be switched off (the camera refused): " + consequence);
        return false;
    }

    // Sets `id` to the wanted value, or to the value the automatic control had settled on.
    void hold(CameraControlId id, std::optional<int64_t> wanted, const std::string& unit) {
        if (!has(id)) {
            if (wanted)
                report.warnings.push_back(std::string("the camera offers no ") +
                                          cameraControlName(id) + " control; " +
                                          std::to_string(*wanted) + " was not set");
            return;
        }
        const int64_t value = wanted.value_or(offered[id].value);
        const std::optional<int64_t> got = device.setControl(id, value);
        if (!got) {
            report.warnings.push_back(std::string("the camera refused ") + cameraControlName(id) +
                                      " " + std::to_string(value));
            return;
        }
        std::string note = std::string(cameraControlName(id)) + " " + std::to_string(*got) + unit;
        if (*got != value) note += " (asked " + std::to_string(value) + ")";
        report.notes.push_back(note);
    }
};

}  // namespace

ExposureLockReport lockExposure(CaptureDevice& device, const ExposureSettings& s) {
    Locker l{device, {}, {}};
    for (const CameraControl& c : device.controls()) l.offered[c.id] = c;
    using Id = CameraControlId;
    const std::string drift =
        "the camera re-exposes as the scene changes, and the virtual objects' shadows and light "
        "will not match the footage; keep the lighting constant and do not point the camera at "
        "lamps or windows";
    if (l.has(Id::AutoExposure)) {
        l.report.exposureLocked = l.switchOff(Id::AutoExposure, drift);
        if (l.report.exposureLocked) l.hold(Id::Exposure, s.exposure, " (x 100 us)");
    } else if (l.has(Id::Exposure)) {
        l.report.exposureLocked = true;  // a manual-only exposure control
        l.hold(Id::Exposure, s.exposure, " (x 100 us)");
    } else {
        l.report.warnings.push_back(
            "the camera offers no exposure control, so automatic exposure (if it has one) "
            "cannot be locked: " +
            drift);
        if (s.exposure) l.report.warnings.push_back("--camera-exposure was not set");
    }
    if (l.has(Id::AutoGain) && l.switchOff(Id::AutoGain, drift)) l.hold(Id::Gain, s.gain, "");
    if (!l.has(Id::AutoGain) && (l.has(Id::Gain) || s.gain)) l.hold(Id::Gain, s.gain, "");
    if (l.has(Id::AutoWhiteBalance)) {
        l.report.whiteBalanceLocked =
            l.switchOff(Id::AutoWhiteBalance,
                        "colours of the footage may drift against the rendered virtual objects");
        if (l.report.whiteBalanceLocked) l.hold(Id::WhiteBalance, s.whiteBalanceK, " K");
    } else if (l.has(Id::WhiteBalance) || s.whiteBalanceK) {
        l.hold(Id::WhiteBalance, s.whiteBalanceK, " K");
    }
    return l.report;
}

}  // namespace mirage
