#pragma once
// Both cameras in one radiometry (docs/environment.md, "Radiometry"): the environment camera's
// gain and white balance relative to the main camera (`radiometry_to_main`), estimated from
// footage in which both see the same part of the room.
//
// A direction both cameras see: a main-camera pixel whose ray leaves the modelled scene (no real
// proxy on it: it sees the room beyond, what L_env stands for) and which the environment camera
// sees from where it is without a real proxy in the way, within its trusted field. For such a
// direction both pixels hold the same radiance (the room is far compared with the distance
// between the cameras), so per channel
//     ratio = main linear value / environment linear value
// is radiometry_to_main. Pairs are kept only where both are well exposed (every 8-bit channel,
// and every bilinear tap of the environment pixel, within the well-exposed codes of
// render/RadiometricRatio.h: not dark, not clipped) and
// smooth (the main pixel's 3 x 3 neighbourhood and the environment pixel's taps within 10 % of
// their mean luminance: an edge moves with a small pose error or with parallax). The estimate is
// the per-channel median of the kept ratios over all frames added: the same estimator
// (RadiometricRatio) as the main camera's per-frame exposure against the rendered real surfaces.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"
#include "core/scene/Scene.h"
#include "render/EnvironmentCamera.h"
#include "render/RadiometricRatio.h"

namespace mirage::raytrace {
class EmbreeDevice;
class RayTracingScene;
}  // namespace mirage::raytrace

namespace mirage::render {

struct RadiometryEstimate {
    std::optional<glm::dvec3> ratio;  // radiometry_to_main (R, G, B); unset: not enough overlap
    int samples = 0;                  // directions used (over all frames)
    int frames = 0;                   // frames that gave at least one
    // Per channel: half the interquartile range of the ratios over their median (relative
    // spread; the median's own uncertainty is smaller by about sqrt(samples)).
    glm::dvec3 spread{0.0};
    std::string whyNot;  // set when ratio is unset: what was missing and what to do
};

class EnvironmentRadiometryEstimator {
public:
    // `scene`: its REAL proxies decide which main-camera rays leave the modelled scene.
    // `main`: the main camera's intrinsics; `env`: the environment camera (its gain is ignored:
    // the ratio is what is estimated).
    EnvironmentRadiometryEstimator(const Scene& scene, const CameraIntrinsics& main,
                                   const EnvironmentCameraSetup& env);
    ~EnvironmentRadiometryEstimator();
    EnvironmentRadiometryEstimator(const EnvironmentRadiometryEstimator&) = delete;
    EnvironmentRadiometryEstimator& operator=(const EnvironmentRadiometryEstimator&) = delete;

    // One pair of frames taken at the same time (8-bit BGR, sRGB-encoded, each its camera's
    // size) with the main camera at T_world_main. Returns the directions it contributed.
    // Throws mirage::Error on a frame of the wrong size or type.
    int addFrame(const cv::Mat& mainBgr8, const Pose& T_world_main, const cv::Mat& envBgr8);

    // At least `minSamples` directions are needed for an estimate.
    RadiometryEstimate estimate(int minSamples = 200) const;

    // Every `stride`-th main-camera pixel in each direction is tried (default 2).
    void setStride(int stride);

private:
    CameraIntrinsics main_;
    EnvironmentCameraSetup env_;
    std::unique_ptr<raytrace::EmbreeDevice> device_;
    std::unique_ptr<raytrace::RayTracingScene> real_;
    RadiometricRatio ratios_;
    int frames_ = 0, stride_ = 2;
};

}  // namespace mirage::render
