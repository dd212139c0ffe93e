#pragma once
// Building blocks of synthetic sessions (`mirage synth`, docs/reference-renderer.md): the camera
// path with exactly known poses, camera models, and the sensor effects applied to a linear render
// before it is encoded like a camera frame (8-bit BGR, sRGB-encoded).
//
// Poses are T_world_camera with OpenCV camera axes (+X right, +Y down, +Z forward); world = glTF
// (metres, +Y up). Times are seconds from the first frame.
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

#include "core/NumberRange.h"
#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"

namespace mirage::raytrace {

// The path has three parts, in order: an orbit around the target, a hand-held hold (smooth
// random shake around a fixed pose) and a fast pan (yaw about the camera's position).
struct CameraPathOptions {
    double duration = 3.0;                             // seconds, whole path
    glm::dvec3 target{0.0, 0.0, 0.0};                  // the orbit looks at this world point
    double radius = 0.42;                              // orbit radius (metres, horizontal)
    double height = 0.32;                              // camera height above the target (metres)
    double orbitStartDeg = -30.0, orbitEndDeg = 30.0;  // orbit azimuth about world +Y; 0 = +Z side
    double orbitFraction = 0.5, shakeFraction = 0.3;   // of the duration; the pan takes the rest
    double shakeTranslation = 0.004;                   // metres (amplitude of each axis)
    double shakeRotationDeg = 0.6;                     // degrees
    double panDeg = 35.0;                              // total yaw of the pan
    uint64_t seed = 1;                                 // shake phases
};

Pose cameraPathPose(const CameraPathOptions& o, double t);
// "orbit", "shake" or "pan".
std::string cameraPathSegment(const CameraPathOptions& o, double t);

// Fields of view the synthetic cameras can be made with (degrees): a pinhole's projection
// degenerates towards 180 degrees; the equidistant fish-eye is kept below 200 (its image circle
// would fold back). `mirage synth` checks --hfov and --env-fov against the same ranges.
inline constexpr NumberRange kPinholeHfovDeg{1, 179, true, true};
inline constexpr NumberRange kFisheyeFovDeg{10, 200, true, false};

// Undistorted pinhole with square pixels and the principal point at the image centre.
CameraIntrinsics pinholeFromHorizontalFov(int width, int height, double hfovDeg);
// Equidistant fish-eye (Kannala-Brandt with k1..k4 = 0): r = f theta, `fovDeg` across the image
// circle's diameter = the square image's width.
CameraIntrinsics equidistantFisheye(int size, double fovDeg);

struct SensorOptions {
    float exposure = 1.0f;  // multiplies linear radiance before encoding
    bool exposureChange =
        false;  // auto-exposure step: x0.55 over 0.25 s, starting at 60 % of the duration
    // A sudden exposure step: from 50 % of the duration on, the exposure is multiplied by this
    // (1 = none), between two frames.
    double exposureStep = 1.0;
    // White-balance drift of the main camera: per-channel gains (R, G, B) that grow linearly
    // from 1 at the first frame to these at the last ((1, 1, 1) = none), as an automatic white
    // balance wandering over a shot.
    glm::dvec3 whiteBalanceDrift{1.0};
    double vignette = 0.0;  // relative darkening at the image corners (0 = none, 0.3 typical)
    double noise = 0.0;     // read-noise sigma in linear units at exposure 1; shot noise
                            // sigma = sqrt(noise * value) (0 = none)
    // The main camera's response: 0 = sRGB encoding; else code = 255 * value^(1 / gamma), a
    // camera whose response is not sRGB (the session's calibration states it).
    double responseGamma = 0.0;
};

// The exposure at time t (seconds) of footage `duration` long: the base exposure with the
// exposure change and the exposure step.
double exposureAt(const SensorOptions& s, double t, double duration);
// The white balance's gains (R, G, B) at time t: 1 at t = 0, whiteBalanceDrift at t = duration.
glm::dvec3 whiteBalanceAt(const SensorOptions& s, double t, double duration);
// Linear RGB float (CV_32FC3) -> 8-bit BGR sRGB as a camera would deliver: vignette, exposure and
// white balance (per-channel gains R, G, B), noise (seeded: same seed = same noise), clamp, sRGB
// encoding (or the gamma response of `s.responseGamma`).
cv::Mat applySensor(const cv::Mat& linearRgb, const SensorOptions& s, double exposure,
                    uint64_t seed, const glm::dvec3& whiteBalance = glm::dvec3(1.0));

}  // namespace mirage::raytrace
