#pragma once
// Environment-camera frames of known environments, for the live-environment tests and
// benchmarks: each camera pixel is unprojected with the calibrated model, turned into a world
// direction and given the environment's radiance there, then encoded like a camera frame (times
// `exposure`, clamped, 8-bit sRGB, BGR). Pixels the model cannot unproject (outside the image
// circle) are black. World = glTF (+Y up); poses are T_world_camera with OpenCV axes.
#include <algorithm>
#include <cmath>
#include <functional>

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/image/ImageIO.h"
#include "core/math/Pose.h"

namespace mirage::test {

using RadianceFn = std::function<glm::vec3(const glm::dvec3& worldDirection)>;

inline cv::Mat renderEnvironmentView(const CameraIntrinsics& K, const Pose& T_world_camera,
                                     const RadianceFn& radiance, float exposure = 1.0f) {
    cv::Mat bgr(K.height, K.width, CV_8UC3, cv::Scalar::all(0));
    const glm::dmat3 R = T_world_camera.rotationMatrix();
    for (int y = 0; y < K.height; ++y)
        for (int x = 0; x < K.width; ++x) {
            const auto ray = K.unproject(glm::dvec2(x, y));
            if (!ray) continue;
            const glm::vec3 L = radiance(glm::normalize(R * *ray)) * exposure;
            cv::Vec3b& px = bgr.at<cv::Vec3b>(y, x);
            for (int c = 0; c < 3; ++c)
                px[2 - c] = cv::saturate_cast<uchar>(
                    std::lround(255.0f * linearToSrgb(std::clamp(L[c], 0.0f, 1.0f))));
        }
    return bgr;
}

// World direction of equirectangular map texel centre (x + 0.5, y + 0.5) of a w x h map
// (docs/environment.md: the centre column looks along -Z, the top row up).
inline glm::dvec3 equirectDirection(double x, double y, int w, int h) {
    const double phi = 2 * M_PI * x / w - M_PI;
    const double lat = 0.5 * M_PI - M_PI * y / h;
    return {std::cos(lat) * std::sin(phi), std::sin(lat), -std::cos(lat) * std::cos(phi)};
}

// The environment as an equirectangular linear RGB map (CV_32FC3), for the static-file path.
inline cv::Mat equirectFromRadiance(const RadianceFn& radiance, int w, int h) {
    cv::Mat m(h, w, CV_32FC3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const glm::vec3 L = radiance(equirectDirection(x + 0.5, y + 0.5, w, h));
            m.at<cv::Vec3f>(y, x) = cv::Vec3f(L.r, L.g, L.b);
        }
    return m;
}

}  // namespace mirage::test
