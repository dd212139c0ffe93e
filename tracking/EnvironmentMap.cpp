#include "tracking/EnvironmentMap.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/camera/EquirectProjection.h"
#include "core/image/ImageIO.h"

namespace mirage::tracking {

EnvironmentMap::EnvironmentMap(int width, int height) {
    if (height <= 0) height = width / 2;
    if (width < 4 || height < 2) throw Error("environment map: size must be at least 4 x 2");
    radiance_ = cv::Mat(height, width, CV_32FC3, cv::Scalar::all(0));
    valid_ = cv::Mat(height, width, CV_8U, cv::Scalar(0));
    clipped_ = cv::Mat(height, width, CV_8U, cv::Scalar(0));
}

void EnvironmentMap::clear() {
    radiance_.setTo(cv::Scalar::all(0));
    valid_.setTo(0);
    clipped_.setTo(0);
}

glm::dvec3 EnvironmentMap::direction(double x, double y, int width, int height) {
    return equirectDirection(x, y, width, height);
}

glm::dvec2 EnvironmentMap::pixel(const glm::dvec3& d, int width, int height) {
    return equirectPixel(d, width, height);
}

double EnvironmentMap::validFraction() const {
    return double(cv::countNonZero(valid_)) / double(valid_.total());
}

void EnvironmentMap::update(const cv::Mat& frame, const CameraIntrinsics& cam,
                            const Pose& T_world_camera, double blend) {
    if (frame.type() != CV_8UC3) throw Error("environment map: frame must be 8-bit BGR");
    if (frame.cols != cam.width || frame.rows != cam.height)
        throw Error("environment map: frame size differs from the fish-eye calibration");
    if (!(blend > 0 && blend <= 1)) throw Error("environment map: blend must be in (0, 1]");
    const cv::Mat linear = srgbBgr8ToLinearRgb(frame);  // CV_32FC3 RGB
    // Where each direction lands in the frame (-1: not seen; core/camera/EquirectProjection.h,
    // without the fill: directions never seen stay invalid).
    const int W = width(), H = height();
    const EquirectLookup lookup = equirectLookup(cam, T_world_camera, W, H, reachDeg_, false);
    const cv::Mat& mapX = lookup.mapX;
    const cv::Mat& mapY = lookup.mapY;
    cv::Mat sampled, sampledBgr;
    cv::remap(linear, sampled, mapX, mapY, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    cv::remap(frame, sampledBgr, mapX, mapY, cv::INTER_NEAREST, cv::BORDER_CONSTANT);
    for (int y = 0; y < H; ++y) {
        const float* mx = mapX.ptr<float>(y);
        const cv::Vec3f* s = sampled.ptr<cv::Vec3f>(y);
        const cv::Vec3b* sb = sampledBgr.ptr<cv::Vec3b>(y);
        cv::Vec3f* r = radiance_.ptr<cv::Vec3f>(y);
        uint8_t* v = valid_.ptr<uint8_t>(y);
        uint8_t* c = clipped_.ptr<uint8_t>(y);
        for (int x = 0; x < W; ++x) {
            if (mx[x] < 0) continue;
            const float w = v[x] ? float(blend) : 1.0f;
            r[x] = (1 - w) * r[x] + w * s[x];
            v[x] = 255;
            c[x] = (sb[x][0] >= 254 || sb[x][1] >= 254 || sb[x][2] >= 254) ? 255 : 0;
        }
    }
}

}  // namespace mirage::tracking
