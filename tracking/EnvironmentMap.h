#pragma once
// An environment map over world directions built from fish-eye camera frames (docs/tracking.md,
// "Environment map"): for L_env and image-based light.
//
// Layout: equirectangular, width x height (height = width / 2 by default), linear RGB float
// (CV_32FC3, channel order R, G, B; values are the camera's linearised sRGB, relative radiance).
// Pixel (x, y), centre at (x + 0.5, y + 0.5), is the world direction (world = glTF, +Y up):
//   longitude phi = 2 pi (x + 0.5) / width - pi          (0 at the image centre column)
//   latitude theta = pi / 2 - pi (y + 0.5) / height      (+pi/2 = straight up, top row)
//   d = (cos theta sin phi, sin theta, -cos theta cos phi)
// So the centre column looks along world -Z, a quarter to the right along +X, the top row up (+Y).
//
// Validity: a direction is valid once a frame has seen it within the fish-eye's calibrated field
// (CameraIntrinsics::project succeeds and lands inside the image). Directions never seen stay
// invalid (radiance 0): nothing is invented. Seen directions keep their last value when later
// frames do not see them. Clipped (saturated) camera pixels are marked in clipped().
//
// Reach: a calibration states the largest angle off its optical axis its data covered; beyond
// it the fish-eye model is extrapolated (pixels of error within a few degrees). With a reach set,
// directions farther off the camera's axis are not sampled: they stay as the unseen part of the
// sphere does (invalid, radiance 0) unless another frame sees them within the reach.
#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"

namespace mirage::tracking {

class EnvironmentMap {
public:
    explicit EnvironmentMap(int width = 512, int height = 0);

    // Updates every direction the frame sees. frame: 8-bit BGR, sRGB-encoded (decoded to linear
    // here). fisheye: its intrinsics (any model; Kannala-Brandt for fish-eyes). T_world_camera:
    // the fish-eye camera's pose (OpenCV axes). blend in (0, 1]: weight of the new frame where
    // the direction was already valid (1 = replace, smaller = running average against noise).
    // Throws mirage::Error on a frame whose size differs from the intrinsics'.
    void update(const cv::Mat& frameBgr8, const CameraIntrinsics& fisheye,
                const Pose& T_world_camera, double blend = 1.0);
    void clear();
    // Largest angle off the fish-eye's optical axis (degrees) sampled from now on; <= 0 = no
    // limit (the calibration does not state its reach: the whole projectable field is used).
    void setReachDeg(double reachDeg) { reachDeg_ = reachDeg; }
    double reachDeg() const { return reachDeg_; }

    const cv::Mat& radiance() const { return radiance_; }  // CV_32FC3 linear RGB
    const cv::Mat& validity() const { return valid_; }     // CV_8U, 255 = seen, 0 = never seen
    const cv::Mat& clipped() const { return clipped_; }    // CV_8U, 255 = last sample saturated
    double validFraction() const;

    int width() const { return radiance_.cols; }
    int height() const { return radiance_.rows; }
    // The mapping above; (x, y) continuous pixel coordinates (centres at +0.5).
    static glm::dvec3 direction(double x, double y, int width, int height);
    static glm::dvec2 pixel(const glm::dvec3& direction, int width, int height);

private:
    cv::Mat radiance_, valid_, clipped_;
    double reachDeg_ = -1;
};

}  // namespace mirage::tracking
