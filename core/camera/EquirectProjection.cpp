#include "core/camera/EquirectProjection.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/Error.h"

namespace mirage {
namespace {

struct Projector {
    const CameraIntrinsics& K;
    double maxTheta;
    // Image position of camera-frame direction d if it is seen.
    std::optional<glm::dvec2> operator()(const glm::dvec3& d) const {
        const double theta = std::atan2(std::hypot(d.x, d.y), d.z);
        if (!(theta <= maxTheta)) return std::nullopt;
        const auto px = K.project(d);
        if (px && px->x >= 0 && px->y >= 0 && px->x <= K.width - 1 && px->y <= K.height - 1)
            return px;
        return std::nullopt;
    }
};

}  // namespace

glm::dvec3 equirectDirection(double x, double y, int width, int height) {
    const double phi = 2 * M_PI * x / width - M_PI;
    const double theta = 0.5 * M_PI - M_PI * y / height;
    return {std::cos(theta) * std::sin(phi), std::sin(theta), -std::cos(theta) * std::cos(phi)};
}

glm::dvec2 equirectPixel(const glm::dvec3& d, int width, int height) {
    const glm::dvec3 n = glm::normalize(d);
    const double phi = std::atan2(n.x, -n.z);
    const double theta = std::asin(std::clamp(n.y, -1.0, 1.0));
    return {(phi + M_PI) / (2 * M_PI) * width, (0.5 * M_PI - theta) / M_PI * height};
}

EquirectLookup equirectLookup(const CameraIntrinsics& K, const Pose& T_world_camera, int W, int H,
                              double reachDeg, bool fill) {
    if (W < 1 || H < 1) throw Error("equirectangular map: size must be positive");
    double maxTheta = K.maxFisheyeTheta;
    if (reachDeg > 0) maxTheta = std::min(maxTheta, reachDeg * M_PI / 180.0);
    const Projector project{K, maxTheta};
    EquirectLookup out;
    out.mapX = cv::Mat(H, W, CV_32F);
    out.mapY = cv::Mat(H, W, CV_32F);
    out.seen = cv::Mat(H, W, CV_8U);
    // Rays are taken into the camera frame with R^T.
    const glm::dmat3 Rt = glm::transpose(T_world_camera.rotationMatrix());
    const glm::dvec2 centre(K.cx, K.cy);
    cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
            float* mx = out.mapX.ptr<float>(y);
            float* my = out.mapY.ptr<float>(y);
            uint8_t* s = out.seen.ptr<uint8_t>(y);
            for (int x = 0; x < W; ++x) {
                const glm::dvec3 d = Rt * equirectDirection(x + 0.5, y + 0.5, W, H);
                auto px = project(d);
                s[x] = px ? 255 : 0;
                if (!px && fill) {
                    const double r = std::hypot(d.x, d.y);
                    const glm::dvec2 az = r > 1e-6 ? glm::dvec2(d.x, d.y) / r : glm::dvec2(1, 0);
                    const double theta = std::atan2(r, d.z);
                    const double target =
                        std::min(theta > 0.5 * M_PI ? M_PI - theta : theta, maxTheta);
                    auto at = [&](double t) {
                        return project(glm::dvec3(az * std::sin(t), std::cos(t)));
                    };
                    double lo = 0, hi = target;
                    if (at(hi)) {
                        lo = hi;
                    } else {
                        for (int i = 0; i < 12; ++i) {
                            const double mid = 0.5 * (lo + hi);
                            (at(mid) ? lo : hi) = mid;
                        }
                    }
                    px = at(lo);
                    if (!px) px = centre;
                }
                mx[x] = px ? float(px->x) : -1.0f;
                my[x] = px ? float(px->y) : -1.0f;
            }
        }
    });
    return out;
}

cv::Mat equirectFromCamera(const cv::Mat& linearRgb, const CameraIntrinsics& K,
                           const Pose& T_world_camera, int W, int H, double reachDeg,
                           cv::Mat* seen) {
    if (linearRgb.type() != CV_32FC3)
        throw Error("equirectangular map: the camera frame must be linear RGB float");
    if (linearRgb.cols != K.width || linearRgb.rows != K.height)
        throw Error("equirectangular map: the frame's size differs from the camera's calibration");
    const EquirectLookup l = equirectLookup(K, T_world_camera, W, H, reachDeg, /*fill=*/true);
    cv::Mat out;
    cv::remap(linearRgb, out, l.mapX, l.mapY, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    if (seen) *seen = l.seen;
    return out;
}

}  // namespace mirage
