#pragma once
// Where a calibrated camera sees each direction of an equirectangular environment map
// (docs/environment.md). One mapping for every user: the offline map of `mirage track --envmap`
// (tracking/EnvironmentMap), the reference renderer's fish-eye environment and the tests of the
// real-time environment pass (render/passes/environment/fisheye_to_equirect.frag, which is this
// code on the GPU).
//
// Layout: pixel (x, y) of a width x height map, centre at (x + 0.5, y + 0.5), is the world
// direction (world = glTF, +Y up)
//   phi = 2 pi x / width - pi, theta = pi / 2 - pi y / height,
//   d = (cos theta sin phi, sin theta, -cos theta cos phi):
// the centre column looks along world -Z, three quarters of the width along +X, the top row up.
//
// Seen: d, rotated into the camera frame (OpenCV axes), is at most maxTheta off the optical axis
// (the calibration's reach, and the model's own limit: CameraIntrinsics::maxFisheyeTheta) and
// projects inside the image (0 .. size - 1, so bilinear taps stay inside).
// Fill (optional) of the unseen directions: the mirror through the camera's image plane (theta
// off the axis -> pi - theta, same azimuth; for a camera looking up, the lower hemisphere is the
// mirror of the upper one), clamped to the largest seen angle at that azimuth (bisection).
#include <optional>

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"

namespace mirage {

glm::dvec3 equirectDirection(double x, double y, int width, int height);
glm::dvec2 equirectPixel(const glm::dvec3& direction, int width, int height);

struct EquirectLookup {
    cv::Mat mapX, mapY;  // CV_32F, width x height: camera image position of each direction
    cv::Mat seen;        // CV_8U: 255 = seen, 0 = not seen (mapX/mapY = -1, or the fill's source)
};

// reachDeg <= 0: no reach (the model's limit only). fill: give unseen directions the fill's image
// position (else -1).
EquirectLookup equirectLookup(const CameraIntrinsics& camera, const Pose& T_world_camera, int width,
                              int height, double reachDeg, bool fill);

// A camera frame (linear RGB float, CV_32FC3) resampled onto a width x height map (bilinear),
// with the unseen part filled as above; `seen` receives the mask (CV_8U, 255 = seen).
cv::Mat equirectFromCamera(const cv::Mat& linearRgb, const CameraIntrinsics& camera,
                           const Pose& T_world_camera, int width, int height, double reachDeg,
                           cv::Mat* seen = nullptr);

}  // namespace mirage
