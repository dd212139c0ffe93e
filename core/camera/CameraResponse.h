#pragma once
// The camera's response: how the 8-bit code a camera delivers relates to the light that reached
// its sensor (docs/camera-matching.md, "Camera response"). mirage composites in linear light, so
// every camera frame is linearised first; without a measured response the footage is taken as
// sRGB-encoded (IEC 61966-2-1), which many webcams only approximate.
//
// The response is stored as its inverse: per channel (R, G, B) and per code 0..255 the relative
// linear value, non-decreasing, 0 at code 0 and 1 at code 255. It lives in the camera's
// calibration file under the key `response` (docs/formats.md).
#include <array>
#include <filesystem>
#include <optional>
#include <string>

namespace mirage {

class CameraResponse {
public:
    enum class Kind { Srgb, Gamma, Table };
    using Curve = std::array<float, 256>;  // code -> relative linear value in [0, 1]

    CameraResponse();  // sRGB
    static CameraResponse srgb() { return {}; }
    // code = 255 * linear^(1/gamma); gamma in [1, 4]. Throws mirage::Error outside.
    static CameraResponse gamma(double gamma);
    // A measured inverse response per channel (R, G, B). Each curve must be finite and
    // non-decreasing; it is normalised to 0 at code 0 and 1 at code 255 (the exposure matching
    // takes the scale). Throws mirage::Error naming the channel and code otherwise.
    static CameraResponse table(const std::array<Curve, 3>& inverseRgb);

    Kind kind() const { return kind_; }
    double gammaValue() const { return gamma_; }  // Gamma only
    bool isSrgb() const { return kind_ == Kind::Srgb; }
    std::string describe() const;  // "sRGB", "gamma 2.4", "measured table"

    // Relative linear value of `code` in channel 0 = R, 1 = G, 2 = B.
    float linear(int channel, int code) const { return inverse_[size_t(channel)][size_t(code)]; }
    // The code this camera gives for a relative linear value (nearest; clamped to [0, 255]).
    int code(int channel, float linear) const;

private:
    Kind kind_ = Kind::Srgb;
    double gamma_ = 0.0;
    std::array<Curve, 3> inverse_{};
};

// The `response` key of a calibration file; unset when the file has none (the sRGB assumption).
// Throws mirage::FileError naming the file and field when it is malformed.
std::optional<CameraResponse> loadCameraResponse(const std::filesystem::path& calibrationFile);
// The same, logged (which response, or that sRGB is assumed and how to measure one); sRGB when
// the file states none.
CameraResponse cameraResponseOrSrgb(const std::filesystem::path& calibrationFile);
// Adds or replaces the key in an existing calibration file (atomically); the rest is kept.
void saveCameraResponse(const std::filesystem::path& calibrationFile,
                        const CameraResponse& response);

}  // namespace mirage
