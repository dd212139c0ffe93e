#pragma once
// Undistorted preview of camera frames with given intrinsics (the wizard's "undistortion
// preview", and a quick visual check of a calibration: straight lines must come out straight).
// Pinhole: the same camera matrix without distortion. Fish-eye: a pinhole view with the fish-eye
// focal length scaled by `fisheyeZoom` (a 180-degree image cannot be shown whole as pinhole).
// Maps are cached and rebuilt only when the intrinsics change.
//
// With a reach (CameraCalibration::reachDeg: the largest angle off the axis the calibration data
// covered), output pixels whose ray lies beyond it are masked black: the model is extrapolated
// there (a fish-eye's error grows to pixels a few degrees past its data).
#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"

namespace mirage::calib {

class Undistorter {
public:
    // 8-bit BGR in, 8-bit BGR out (same encoding, sRGB; bilinear interpolation of encoded values,
    // fine for a preview).
    // reachDeg <= 0: no mask.
    cv::Mat apply(const cv::Mat& bgr, const CameraIntrinsics& intrinsics, double fisheyeZoom = 0.5,
                  double reachDeg = -1);
    // Share of the output masked as beyond the reach in the last apply() (0..1).
    double maskedFraction() const { return maskedFraction_; }

private:
    CameraIntrinsics cached_;
    double cachedZoom_ = -1, cachedReach_ = 0;
    cv::Mat map1_, map2_;
    cv::Mat beyondReach_;  // CV_8U, 255 where the output pixel's ray is beyond the reach
    double maskedFraction_ = 0;
};

}  // namespace mirage::calib
