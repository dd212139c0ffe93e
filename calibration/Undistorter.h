#pragma once
// Undistorted preview of camera frames with given intrinsics (the wizard's "undistortion
// preview", and a quick visual check of a calibration: straight lines must come out straight).
// Pinhole: the same camera matrix without distortion. Fish-eye: a pinhole view with the fish-eye
// focal length scaled by `fisheyeZoom` (a 180-degree image cannot be shown whole as pinhole).
// Maps are cached and rebuilt only when the intrinsics change.
#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"

namespace mirage::calib {

class Undistorter {
public:
    // 8-bit BGR in, 8-bit BGR out (same encoding, sRGB; bilinear interpolation of encoded values,
    // fine for a preview).
    cv::Mat apply(const cv::Mat& bgr, const CameraIntrinsics& intrinsics, double fisheyeZoom = 0.5);

private:
    CameraIntrinsics cached_;
    double cachedZoom_ = -1;
    cv::Mat map1_, map2_;
};

}  // namespace mirage::calib
