#include "tracking/EnvironmentMap.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/Error.h"
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
    const double phi = 2 * M_PI * x / width - M_PI;
    const double theta = 0.5 * M_PI - M_PI * y / height;
    return {std::cos(theta) * std::sin(phi), std::sin(theta), -std::cos(theta) * std::cos(phi)};
}

glm::dvec2 EnvironmentMap::pixel(const glm::dvec3& d, int width, int height) {
    const glm::dvec3 n = glm::normalize(d);
    const double phi = std::atan2(n.x, -n.z);
    const double theta = std::asin(std::clamp(n.y, -1.0, 1.0));
    return {(phi + M_PI) / (2 * M_PI) * width, (0.5 * M_PI - theta) / M_PI * height};
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
    const int W = width(), H = height();
    // Where each direction lands in the frame (-1: not seen). Rays are taken into the camera frame
    // with R^T; project() refuses rays beyond the calibrated field of view.
    cv::Mat mapX(H, W, CV_32F), mapY(H, W, CV_32F);
    const glm::dmat3 Rt = glm::transpose(T_world_camera.rotationMatrix());
    // Beyond the calibration's reach: cos(angle off the +Z optical axis) below this.
    const double minCosOffAxis =
        reachDeg_ > 0 ? std::cos(std::min(reachDeg_, 180.0) * M_PI / 180.0) : -2.0;
    cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
            float* mx = mapX.ptr<float>(y);
            float* my = mapY.ptr<float>(y);
            for (int x = 0; x < W; ++x) {
                const glm::dvec3 dCam = Rt * direction(x + 0.5, y + 0.5, W, H);
                const auto px =
                    dCam.z < minCosOffAxis * glm::length(dCam) ? std::nullopt : cam.project(dCam);
                // Inside the image with a half-pixel margin so bilinear sampling stays in it.
                if (px && px->x >= 0 && px->y >= 0 && px->x <= cam.width - 1 &&
                    px->y <= cam.height - 1) {
                    mx[x] = float(px->x);
                    my[x] = float(px->y);
                } else {
                    mx[x] = my[x] = -1.0f;
                }
            }
        }
    });
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
