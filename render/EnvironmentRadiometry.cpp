#include "render/EnvironmentRadiometry.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "core/Error.h"
#include "core/image/ImageIO.h"
#include "render/raytrace/EmbreeDevice.h"
#include "render/raytrace/RayTracingScene.h"

namespace mirage::render {
namespace {

constexpr double kMaxRelativeVariation = 0.10;  // of a pixel's neighbourhood (edges are unusable)
constexpr float kFar = 1e6f;                    // metres: "leaves the modelled scene"

bool wellExposed(const cv::Vec3b& v) {
    for (int c = 0; c < 3; ++c)
        if (!wellExposedCode(v[c])) return false;
    return true;
}

struct Linearise {
    std::array<double, 256> lut{};
    Linearise() {
        for (int v = 0; v < 256; ++v) lut[size_t(v)] = srgbToLinear(float(v) / 255.0f);
    }
    // Linear R, G, B of a BGR pixel.
    glm::dvec3 operator()(const cv::Vec3b& v) const { return {lut[v[2]], lut[v[1]], lut[v[0]]}; }
};

double luminance(const glm::dvec3& c) {
    return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
}

// True when the luminances are all within kMaxRelativeVariation of their mean.
bool smooth(const double* lum, int n) {
    double mean = 0;
    for (int i = 0; i < n; ++i) mean += lum[i];
    mean /= n;
    for (int i = 0; i < n; ++i)
        if (std::abs(lum[i] - mean) > kMaxRelativeVariation * mean) return false;
    return mean > 0;
}

}  // namespace

EnvironmentRadiometryEstimator::EnvironmentRadiometryEstimator(const Scene& scene,
                                                               const CameraIntrinsics& main,
                                                               const EnvironmentCameraSetup& env)
    : main_(main),
      env_(env),
      device_(std::make_unique<raytrace::EmbreeDevice>()),
      real_(std::make_unique<raytrace::RayTracingScene>(scene, raytrace::SceneSubset::RealOnly,
                                                        *device_)) {
    if (!main.isValid() || !env.intrinsics.isValid())
        throw Error("radiometry estimate: invalid camera intrinsics");
}

EnvironmentRadiometryEstimator::~EnvironmentRadiometryEstimator() = default;

void EnvironmentRadiometryEstimator::setStride(int stride) {
    if (stride < 1 || stride > 64) throw Error("radiometry estimate: stride must be 1..64");
    stride_ = stride;
}

int EnvironmentRadiometryEstimator::addFrame(const cv::Mat& mainBgr, const Pose& T_world_main,
                                             const cv::Mat& envBgr) {
    const CameraIntrinsics& E = env_.intrinsics;
    if (mainBgr.type() != CV_8UC3 || mainBgr.cols != main_.width || mainBgr.rows != main_.height)
        throw Error(fmt::format(
            "radiometry estimate: the main camera's frame is {}x{} (type {}), its calibration "
            "{}x{} 8-bit BGR",
            mainBgr.cols, mainBgr.rows, mainBgr.type(), main_.width, main_.height));
    if (envBgr.type() != CV_8UC3 || envBgr.cols != E.width || envBgr.rows != E.height)
        throw Error(fmt::format(
            "radiometry estimate: the environment camera's frame is {}x{} (type {}), its "
            "calibration {}x{} 8-bit BGR",
            envBgr.cols, envBgr.rows, envBgr.type(), E.width, E.height));
    static const Linearise linear;
    const Pose T_world_env = env_.poseInWorld(T_world_main);
    const glm::dmat3 R_world_main = T_world_main.rotationMatrix();
    const glm::dmat3 R_env_world = glm::transpose(T_world_env.rotationMatrix());
    const glm::vec3 mainCentre(T_world_main.translation), envCentre(T_world_env.translation);
    double maxTheta = E.maxFisheyeTheta;
    if (env_.reachDeg > 0) maxTheta = std::min(maxTheta, env_.reachDeg * M_PI / 180.0);

    int added = 0;
    for (int y = 1; y + 1 < mainBgr.rows; y += stride_)
        for (int x = 1; x + 1 < mainBgr.cols; x += stride_) {
            // The main pixel: well exposed and smooth.
            double lum9[9];
            bool ok = true;
            for (int k = 0; k < 9 && ok; ++k) {
                const cv::Vec3b& v = mainBgr.at<cv::Vec3b>(y + k / 3 - 1, x + k % 3 - 1);
                ok = wellExposed(v);
                lum9[k] = luminance(linear(v));
            }
            if (!ok || !smooth(lum9, 9)) continue;
            // Its ray leaves the modelled scene ...
            const auto ray = main_.unproject(glm::dvec2(x, y));
            if (!ray) continue;
            const glm::dvec3 d = glm::normalize(R_world_main * *ray);
            if (real_->occluded(mainCentre, glm::vec3(d), kFar)) continue;
            // ... and the environment camera sees that direction, nothing real in the way.
            const glm::dvec3 dEnv = R_env_world * d;
            if (!(std::atan2(std::hypot(dEnv.x, dEnv.y), dEnv.z) <= maxTheta)) continue;
            const auto px = E.project(dEnv);
            if (!px || px->x < 0 || px->y < 0 || px->x > E.width - 2 || px->y > E.height - 2)
                continue;
            if (real_->occluded(envCentre, glm::vec3(d), kFar)) continue;
            const int x0 = int(px->x), y0 = int(px->y);
            const double fx = px->x - x0, fy = px->y - y0;
            glm::dvec3 envValue(0.0);
            double lum4[4];
            for (int k = 0; k < 4 && ok; ++k) {
                const cv::Vec3b& v = envBgr.at<cv::Vec3b>(y0 + k / 2, x0 + k % 2);
                ok = wellExposed(v);
                const glm::dvec3 c = linear(v);
                lum4[k] = luminance(c);
                envValue += c * ((k % 2 ? fx : 1 - fx) * (k / 2 ? fy : 1 - fy));
            }
            if (!ok || !smooth(lum4, 4)) continue;
            const glm::dvec3 mainValue = linear(mainBgr.at<cv::Vec3b>(y, x));
            if (ratios_.add(mainValue, envValue)) ++added;
        }
    if (added > 0) ++frames_;
    return added;
}

RadiometryEstimate EnvironmentRadiometryEstimator::estimate(int minSamples) const {
    RadiometryEstimate r;
    r.samples = ratios_.size();
    r.frames = frames_;
    if (r.samples < std::max(minSamples, 1)) {
        r.whyNot = fmt::format(
            "the main camera saw {} direction(s) that the environment camera also sees (rays that "
            "leave the modelled scene, well exposed in both, away from edges); at least {} are "
            "needed. Film part of the room beyond the modelled scene (walls, ceiling) with the "
            "main camera while the environment camera sees it too, or set radiometry_to_main in "
            "the environment camera's calibration by hand",
            r.samples, minSamples);
        return r;
    }
    const std::optional<RatioStatistics> stats = ratios_.statistics(minSamples);
    r.ratio = stats->ratio;
    r.spread = stats->spread;
    return r;
}

}  // namespace mirage::render
