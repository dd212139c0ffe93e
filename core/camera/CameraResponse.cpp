#include "core/camera/CameraResponse.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <opencv2/core.hpp>

#include "core/Error.h"
#include "core/camera/CalibrationKey.h"
#include "core/image/ImageIO.h"

namespace mirage {

namespace {
constexpr const char* kKey = "response";
constexpr const char* kChannelKeys[3] = {"inverse_r", "inverse_g", "inverse_b"};
constexpr double kMinGamma = 1.0, kMaxGamma = 4.0;

}  // namespace

CameraResponse::CameraResponse() {
    for (auto& c : inverse_)
        for (int i = 0; i < 256; ++i) c[size_t(i)] = srgbToLinear(float(i) / 255.0f);
}

CameraResponse CameraResponse::gamma(double g) {
    if (!(std::isfinite(g) && g >= kMinGamma && g <= kMaxGamma))
        throw Error(
            fmt::format("camera response gamma {} is outside [{}, {}]", g, kMinGamma, kMaxGamma));
    CameraResponse r;
    r.kind_ = Kind::Gamma;
    r.gamma_ = g;
    for (auto& c : r.inverse_)
        for (int i = 0; i < 256; ++i) c[size_t(i)] = float(std::pow(double(i) / 255.0, g));
    return r;
}

CameraResponse CameraResponse::table(const std::array<Curve, 3>& inverseRgb) {
    static const char* names[3] = {"R", "G", "B"};
    CameraResponse r;
    r.kind_ = Kind::Table;
    for (int ch = 0; ch < 3; ++ch) {
        const Curve& c = inverseRgb[size_t(ch)];
        for (int i = 0; i < 256; ++i) {
            if (!std::isfinite(c[size_t(i)]))
                throw Error(
                    fmt::format("camera response: channel {} code {} is not finite", names[ch], i));
            if (i > 0 && c[size_t(i)] < c[size_t(i - 1)])
                throw Error(
                    fmt::format("camera response: channel {} decreases at code {} ({} < "
                                "{}); a response must not decrease",
                                names[ch], i, c[size_t(i)], c[size_t(i - 1)]));
        }
        const float lo = c[0], span = c[255] - c[0];
        if (!(span > 0))
            throw Error(
                fmt::format("camera response: channel {} is flat (code 0 and code 255 "
                            "give the same light)",
                            names[ch]));
        for (int i = 0; i < 256; ++i)
            r.inverse_[size_t(ch)][size_t(i)] = (c[size_t(i)] - lo) / span;
    }
    return r;
}

std::string CameraResponse::describe() const {
    switch (kind_) {
        case Kind::Srgb:
            return "sRGB";
        case Kind::Gamma:
            return fmt::format("gamma {:.3g}", gamma_);
        case Kind::Table:
            return "measured table";
    }
    return "?";
}

int CameraResponse::code(int channel, float linear) const {
    const Curve& c = inverse_[size_t(channel)];
    if (!(linear > c[0])) return 0;  // also NaN
    if (linear >= c[255]) return 255;
    const auto it = std::lower_bound(c.begin(), c.end(), linear);
    const int hi = int(it - c.begin());
    const int lo = hi - 1;
    return (linear - c[size_t(lo)] <= c[size_t(hi)] - linear) ? lo : hi;
}

std::optional<CameraResponse> loadCameraResponse(const std::filesystem::path& file) {
    const std::string name = file.string();
    try {
        cv::FileStorage fs(name, cv::FileStorage::READ);
        if (!fs.isOpened()) throw FileError(name, "cannot be read as a YAML file");
        const cv::FileNode n = fs[kKey];
        if (n.empty()) return std::nullopt;
        if (!n.isMap())
            throw FileError(name, fmt::format("{}: expected a mapping with a 'kind'", kKey));
        const cv::FileNode kind = n["kind"];
        if (!kind.isString())
            throw FileError(
                name, fmt::format("{}.kind: expected \"srgb\", \"gamma\" or \"table\"", kKey));
        const std::string k = kind.string();
        if (k == "srgb") return CameraResponse::srgb();
        if (k == "gamma") {
            const cv::FileNode g = n["gamma"];
            if (!g.isReal() && !g.isInt())
                throw FileError(name, fmt::format("{}.gamma: expected a number", kKey));
            try {
                return CameraResponse::gamma(double(g));
            } catch (const Error& e) {
                throw FileError(name, fmt::format("{}.gamma: {}", kKey, e.what()));
            }
        }
        if (k != "table")
            throw FileError(name, fmt::format("{}.kind: '{}' is not \"srgb\", \"gamma\" or "
                                              "\"table\"",
                                              kKey, k));
        std::array<CameraResponse::Curve, 3> curves{};
        for (int ch = 0; ch < 3; ++ch) {
            const cv::FileNode c = n[kChannelKeys[ch]];
            if (!c.isSeq() || c.size() != 256)
                throw FileError(name, fmt::format("{}.{}: expected 256 numbers (code 0..255)", kKey,
                                                  kChannelKeys[ch]));
            int i = 0;
            for (auto it = c.begin(); it != c.end(); ++it, ++i) {
                if (!(*it).isReal() && !(*it).isInt())
                    throw FileError(name, fmt::format("{}.{}[{}]: expected a number", kKey,
                                                      kChannelKeys[ch], i));
                curves[size_t(ch)][size_t(i)] = float(double(*it));
            }
        }
        try {
            return CameraResponse::table(curves);
        } catch (const Error& e) {
            throw FileError(name, fmt::format("{}: {}", kKey, e.what()));
        }
    } catch (const cv::Exception& e) {
        throw FileError(name, std::string("not valid YAML: ") + e.what());
    } catch (const std::length_error& e) {
        throw FileError(name, std::string("not valid YAML: ") + e.what());
    }
}

CameraResponse cameraResponseOrSrgb(const std::filesystem::path& file) {
    if (std::optional<CameraResponse> r = loadCameraResponse(file)) {
        spdlog::info("camera response: {} (from {})", r->describe(), file.string());
        return *r;
    }
    spdlog::info(
        "camera response: {} states none; the footage is taken as sRGB (measure one with "
        "`mirage response`, docs/camera-matching.md)",
        file.string());
    return CameraResponse::srgb();
}

void saveCameraResponse(const std::filesystem::path& file, const CameraResponse& r) {
    std::string value;
    switch (r.kind()) {
        case CameraResponse::Kind::Srgb:
            value = "{ kind: srgb }";
            break;
        case CameraResponse::Kind::Gamma:
            value = fmt::format("{{ kind: gamma, gamma: {:.17g} }}", r.gammaValue());
            break;
        case CameraResponse::Kind::Table: {
            value = "{ kind: table";
            for (int ch = 0; ch < 3; ++ch) {
                std::vector<std::string> v;
                for (int i = 0; i < 256; ++i) v.push_back(fmt::format("{:.9g}", r.linear(ch, i)));
                value += fmt::format(", {}: [ {} ]", kChannelKeys[ch], fmt::join(v, ", "));
            }
            value += " }";
            break;
        }
    }
    setCalibrationKey(file, kKey, value);
}

}  // namespace mirage
