#include "calibration/Undistorter.h"

#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "calibration/Calibrator.h"

namespace mirage::calib {

namespace {
bool same(const CameraIntrinsics& a, const CameraIntrinsics& b) {
    return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy &&
           a.cx == b.cx && a.cy == b.cy && a.model == b.model && a.distortion == b.distortion;
}
}  // namespace

cv::Mat Undistorter::apply(const cv::Mat& bgr, const CameraIntrinsics& in, double fisheyeZoom,
                           double reachDeg) {
    if (map1_.empty() || !same(in, cached_) || fisheyeZoom != cachedZoom_ ||
        reachDeg != cachedReach_) {
        const cv::Size size(in.width, in.height);
        const cv::Mat K = cameraMatrix(in), D = distortionVector(in);
        // The output is a pinhole view with focal lengths (fx, fy) (fish-eye: scaled by the
        // zoom): its pixel (u, v) looks along ((u - cx) / fx, (v - cy) / fy, 1).
        const double zoom = in.model == DistortionModel::KannalaBrandt ? fisheyeZoom : 1.0;
        beyondReach_ = cv::Mat::zeros(size, CV_8U);
        maskedFraction_ = 0;
        if (reachDeg > 0) {
            const double limit = std::tan(std::min(reachDeg, 89.9) * M_PI / 180.0);
            for (int v = 0; v < size.height; ++v)
                for (int u = 0; u < size.width; ++u) {
                    const double x = (u - in.cx) / (in.fx * zoom), y = (v - in.cy) / (in.fy * zoom);
                    if (x * x + y * y > limit * limit) beyondReach_.at<uint8_t>(v, u) = 255;
                }
            maskedFraction_ = cv::countNonZero(beyondReach_) / double(size.area());
        }
        if (in.model == DistortionModel::KannalaBrandt) {
            cv::Mat Knew = K.clone();
            Knew.at<double>(0, 0) *= fisheyeZoom;
            Knew.at<double>(1, 1) *= fisheyeZoom;
            cv::fisheye::initUndistortRectifyMap(K, D, cv::Mat::eye(3, 3, CV_64F), Knew, size,
                                                 CV_16SC2, map1_, map2_);
        } else {
            cv::initUndistortRectifyMap(K, D, cv::Mat(), K, size, CV_16SC2, map1_, map2_);
        }
        cached_ = in;
        cachedZoom_ = fisheyeZoom;
        cachedReach_ = reachDeg;
    }
    cv::Mat out;
    cv::remap(bgr, out, map1_, map2_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    if (maskedFraction_ > 0) out.setTo(cv::Scalar::all(0), beyondReach_);
    return out;
}

}  // namespace mirage::calib
