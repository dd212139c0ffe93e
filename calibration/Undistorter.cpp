#include "calibration/Undistorter.h"

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

cv::Mat Undistorter::apply(const cv::Mat& bgr, const CameraIntrinsics& in, double fisheyeZoom) {
    if (map1_.empty() || !same(in, cached_) || fisheyeZoom != cachedZoom_) {
        const cv::Size size(in.width, in.height);
        const cv::Mat K = cameraMatrix(in), D = distortionVector(in);
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
    }
    cv::Mat out;
    cv::remap(bgr, out, map1_, map2_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    return out;
}

}  // namespace mirage::calib
