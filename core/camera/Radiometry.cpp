#include "core/camera/Radiometry.h"

#include <cmath>

#include <fmt/format.h>
#include <opencv2/core.hpp>

#include "core/Error.h"
#include "core/camera/CalibrationKey.h"

namespace mirage {

namespace {
constexpr const char* kKey = "radiometry_to_main";
}

std::optional<glm::dvec3> loadRadiometryToMain(const std::filesystem::path& file) {
    std::vector<double> v;
    try {
        cv::FileStorage fs(file.string(), cv::FileStorage::READ);
        if (!fs.isOpened()) throw FileError(file.string(), "cannot be read as a YAML file");
        const cv::FileNode n = fs[kKey];
        if (n.empty()) return std::nullopt;
        if (!n.isSeq())
            throw FileError(file.string(),
                            fmt::format("{}: expected a sequence of 3 numbers (R, G, B)", kKey));
        for (auto it = n.begin(); it != n.end(); ++it) {
            if (!(*it).isReal() && !(*it).isInt())
                throw FileError(file.string(), fmt::format("{}: expected numbers", kKey));
            v.push_back(double(*it));
        }
    } catch (const cv::Exception& e) {
        throw FileError(file.string(), std::string("not valid YAML: ") + e.what());
    } catch (const std::length_error& e) {
        throw FileError(file.string(), std::string("not valid YAML: ") + e.what());
    }
    if (v.size() != 3)
        throw FileError(file.string(),
                        fmt::format("{}: expected 3 numbers (R, G, B), got {}", kKey, v.size()));
    for (double x : v)
        if (!(std::isfinite(x) && x > 0))
            throw FileError(file.string(),
                            fmt::format("{}: every gain must be finite and positive", kKey));
    return glm::dvec3(v[0], v[1], v[2]);
}

void saveRadiometryToMain(const std::filesystem::path& file, const glm::dvec3& r) {
    for (int i = 0; i < 3; ++i)
        if (!(std::isfinite(r[i]) && r[i] > 0))
            throw Error(fmt::format("{}: every gain must be finite and positive", kKey));
    setCalibrationKey(file, kKey, fmt::format("[ {:.17g}, {:.17g}, {:.17g} ]", r.x, r.y, r.z));
}

}  // namespace mirage
