#pragma once
// Camera intrinsics with lens distortion, in OpenCV's conventions (docs/conventions.md):
// pixel (0,0) is the centre of the top-left pixel; camera frame +X right, +Y down, +Z forward.
//
//  - BrownConrady: OpenCV's pinhole model ("plumb_bob"), coefficients k1, k2, p1, p2, k3.
//  - KannalaBrandt: OpenCV's fisheye model ("equidistant"), coefficients k1..k4, on
//    theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8).
//
// project() and unproject() are written out here (not cv::projectPoints) so that per-point use in
// renderers and trackers costs no allocation; tests check them against OpenCV.
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace mirage {

enum class DistortionModel { BrownConrady, KannalaBrandt };

// "plumb_bob" / "fisheye" (ROS also says "equidistant"); throws mirage::Error on others.
DistortionModel distortionModelFromName(const std::string& name);
const char* distortionModelName(DistortionModel m);

struct CameraIntrinsics {
    int width = 0, height = 0;  // pixels
    double fx = 0, fy = 0, cx = 0, cy = 0;
    DistortionModel model = DistortionModel::BrownConrady;
    // BrownConrady: k1, k2, p1, p2, k3 (missing ones are 0). KannalaBrandt: k1..k4.
    std::vector<double> distortion;

    // Point in the camera frame (metres) to pixel. Points behind the camera (z <= 0 for the
    // pinhole model; theta beyond maxFisheyeTheta for the fish-eye model) give std::nullopt.
    std::optional<glm::dvec2> project(const glm::dvec3& pointCamera) const;
    // project() and its derivative: column a of dPixelDPoint is d(pixel)/d(pointCamera[a])
    // (pixels per metre). Closed form for BrownConrady; forward differences for KannalaBrandt.
    // The pixel is exactly project()'s.
    std::optional<glm::dvec2> projectWithJacobian(const glm::dvec3& pointCamera,
                                                  glm::dmat3x2& dPixelDPoint) const;
    // Pixel to unit ray direction in the camera frame. Iterative inversion of the distortion;
    // std::nullopt where it does not converge (far outside the calibrated field of view).
    std::optional<glm::dvec3> unproject(const glm::dvec2& pixel) const;

    // Distort / undistort normalised coordinates (x/z, y/z) for BrownConrady, or for the fish-eye
    // model the undistorted "ideal" point tan(theta)*dir. Exposed for tests and GPU code.
    glm::dvec2 distortNormalized(const glm::dvec2& xy) const;

    // Largest angle off the optical axis (radians) the model is trusted at: 90 deg for fish-eye
    // (the polynomial is only monotonic over the calibrated range), or the corner angle for
    // pinhole.
    double maxFisheyeTheta = 1.5707963267948966;

    double coeff(size_t i) const { return i < distortion.size() ? distortion[i] : 0.0; }
    bool isValid() const;  // finite positive focal lengths and image size
};

}  // namespace mirage
