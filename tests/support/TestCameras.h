#pragma once
// Camera intrinsics the tests share. The values are plausible for a webcam and a fish-eye lens;
// they come from no real device. Pixels; OpenCV conventions (docs/conventions.md).
#include <utility>
#include <vector>

#include "core/camera/CameraModel.h"

namespace mirage::test {

inline CameraIntrinsics pinholeCamera(int width, int height, double fx, double fy, double cx,
                                      double cy, std::vector<double> brownConrady = {}) {
    CameraIntrinsics c;
    c.width = width;
    c.height = height;
    c.fx = fx;
    c.fy = fy;
    c.cx = cx;
    c.cy = cy;
    c.model = DistortionModel::BrownConrady;
    c.distortion = std::move(brownConrady);  // k1, k2, p1, p2, k3
    return c;
}

inline CameraIntrinsics fisheyeCamera(int width, int height, double fx, double fy, double cx,
                                      double cy, std::vector<double> kannalaBrandt) {
    CameraIntrinsics c = pinholeCamera(width, height, fx, fy, cx, cy, std::move(kannalaBrandt));
    c.model = DistortionModel::KannalaBrandt;  // k1..k4
    return c;
}

// 640x480 webcam with strong barrel distortion: the calibration tests' default camera.
inline CameraIntrinsics distortedWebcam640() {
    return pinholeCamera(640, 480, 520, 518, 322.5, 238, {-0.25, 0.08, 0.0008, -0.0006, -0.01});
}

}  // namespace mirage::test
