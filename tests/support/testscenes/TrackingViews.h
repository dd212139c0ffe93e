#pragma once
// Shared helpers of the tracking tests: cameras and poses for synthetic board views.
#include <cmath>

#include "core/camera/CameraModel.h"
#include "core/image/ImageIO.h"
#include "core/math/Pose.h"
#include "testscenes/LookAt.h"
#include "tracking/BoardImage.h"
#include "tracking/BoardLayout.h"
#include "tracking/SyntheticBoardView.h"

namespace mirage::tracking::testing {

// test::lookAt with the board's far edge (-Z) up in the image by default.
inline Pose lookAt(const glm::dvec3& eye, const glm::dvec3& target,
                   const glm::dvec3& up = glm::dvec3(0, 0, -1), double rollRad = 0.0) {
    return test::lookAt(eye, target, up, rollRad);
}

// A camera position on a sphere of `dist` metres around the board's centre (the page's origin):
// elevation above the page and azimuth from +Z towards +X, in degrees.
inline glm::dvec3 orbit(double dist, double elevDeg, double azDeg) {
    const double el = glm::radians(elevDeg), az = glm::radians(azDeg);
    return dist *
           glm::dvec3(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
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

// A fish-eye whose image circle holds the whole hemisphere (90 degrees reach r = 0.97 w/2).
inline CameraIntrinsics hemisphereFisheye(int size) {
    CameraIntrinsics c = fisheyeCamera(size, size);
    c.fx = c.fy = 0.5 * size / 1.7;
    return c;
}

// A known environment: smooth colour gradients plus a bright soft "window" (linear RGB).
inline glm::dvec3 trueEnvironment(const glm::dvec3& d) {
    const glm::dvec3 window = glm::normalize(glm::dvec3(0.4, 0.7, -0.6));
    const double spot = std::exp(-(1.0 - glm::dot(d, window)) * 25.0);
    return {0.35 + 0.25 * d.x + 0.5 * spot, 0.4 + 0.3 * d.y + 0.4 * spot,
            0.3 + 0.2 * std::sin(3 * d.z) + 0.3 * spot};
}

// What a fish-eye camera at T_world_camera records of that environment: each pixel unprojected
// to a ray, rotated into the world, the environment sampled, encoded to 8-bit sRGB BGR.
inline cv::Mat renderFisheye(const CameraIntrinsics& cam, const Pose& T_world_camera) {
    cv::Mat out(cam.height, cam.width, CV_8UC3, cv::Scalar::all(0));
    const glm::dmat3 R = T_world_camera.rotationMatrix();
    for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) {
            const auto ray = cam.unproject({x, y});
            if (!ray) continue;
            const glm::dvec3 c = trueEnvironment(R * *ray);
            auto enc = [](double v) {
                return uint8_t(std::lround(255.0 * linearToSrgb(float(std::clamp(v, 0.0, 1.0)))));
            };
            out.at<cv::Vec3b>(y, x) = {enc(c.b), enc(c.g), enc(c.r)};
        }
    return out;
}

// The default board (BoardLayout) with its raster at 8000 px/m and a pinhole camera: renders
// synthetic views of the board, shared per test process (the raster takes a moment).
struct BoardViewScene {
    Board board = BoardLayout().makeBoard();
    BoardRaster tex = renderBoard(board, 8000, false);
    CameraIntrinsics cam = pinholeCamera();
    cv::Mat render(const Pose& T_world_camera) const {
        return renderSyntheticBoardView(board, tex, cam, T_world_camera);
    }
};

inline const BoardViewScene& boardViewScene() {
    static const BoardViewScene s;
    return s;
}

}  // namespace mirage::tracking::testing
