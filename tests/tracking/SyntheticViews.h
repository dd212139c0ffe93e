#pragma once
// Shared helpers of the tracking tests: cameras and poses for synthetic board views.
#include <cmath>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"
#include "tracking/BoardLayout.h"
#include "tracking/SyntheticBoardView.h"

namespace mirage::tracking::testing {

// T_world_camera (OpenCV camera axes) at `eye` looking at `target`; `up` is the world direction
// that appears up in the image; `rollRad` turns the camera about its optical axis.
inline Pose lookAt(const glm::dvec3& eye, const glm::dvec3& target,
                   const glm::dvec3& up = glm::dvec3(0, 0, -1), double rollRad = 0.0) {
    const glm::dvec3 fwd = glm::normalize(target - eye);
    glm::dvec3 right = glm::normalize(glm::cross(fwd, up));
    glm::dvec3 down = glm::cross(fwd, right);
    const glm::dvec3 r2 = std::cos(rollRad) * right + std::sin(rollRad) * down;
    down = glm::cross(fwd, r2);
    return Pose::fromRotationTranslation(glm::dmat3(r2, down, fwd), eye);
}

inline CameraIntrinsics pinholeCamera(int w = 640, int h = 480, double f = 600) {
    CameraIntrinsics c;
    c.width = w;
    c.height = h;
    c.fx = c.fy = f;
    c.cx = (w - 1) * 0.5 + 3.2;
    c.cy = (h - 1) * 0.5 - 2.1;
    c.model = DistortionModel::BrownConrady;
    c.distortion = {-0.12, 0.05, 0.0005, -0.0003, 0.0};
    return c;
}

inline CameraIntrinsics fisheyeCamera(int w = 800, int h = 800) {
    CameraIntrinsics c;
    c.width = w;
    c.height = h;
    c.fx = c.fy = 250;
    c.cx = (w - 1) * 0.5;
    c.cy = (h - 1) * 0.5;
    c.model = DistortionModel::KannalaBrandt;
    c.distortion = {0.02, -0.005, 0.001, -0.0002};
    return c;
}

}  // namespace mirage::tracking::testing
