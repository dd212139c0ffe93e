#pragma once
// Camera calibration files: OpenCV FileStorage YAML with the keys OpenCV's calibration sample
// writes (docs/formats.md). Reads both key styles (camera_matrix / distortion_coefficients and
// cameraMatrix / dist_coeffs). mirage adds: distortion_model ("plumb_bob" | "fisheye"),
// per-parameter standard deviations, per-view errors, a reliability flag with its reason, and an
// optional extrinsic pose of this camera relative to the main camera or the world.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"

namespace mirage {

struct CameraCalibration {
    CameraIntrinsics intrinsics;
    double avgReprojectionError = -1;  // pixels RMS; < 0 = unknown
    // Standard deviations in the order fx, fy, cx, cy, then the distortion coefficients.
    std::vector<double> stdDeviations;
    std::vector<double> perViewErrors;  // pixels RMS per view
    int viewCount = 0;
    // Reach: how far the calibration data goes. reachDeg = the largest angle off the optical axis
    // (degrees) of a corner the calibration used; reachRadiusPx = the largest distance of one
    // from the principal point (pixels). Beyond them the model is extrapolated (a fish-eye's
    // error grows fast there). <= 0 = unknown (older files).
    double reachDeg = -1, reachRadiusPx = -1;
    bool reliable = true;
    std::string unreliableReason;  // set when !reliable: why the numbers should not be trusted
    // Extrinsic pose T_parent_camera, parent is "main" (the main camera, OpenCV axes) or "world".
    std::optional<Pose> T_parent_camera;
    std::string extrinsicParent;
};

// Throws mirage::FileError naming the file and the missing/bad key.
CameraCalibration loadCalibration(const std::filesystem::path& path);
// Writes atomically (temporary file + rename), so a crash never leaves a half-written file.
void saveCalibration(const std::filesystem::path& path, const CameraCalibration& calib);
// ROS camera_info YAML (camera_name, image_width, image_height, camera_matrix, distortion_model,
// distortion_coefficients, rectification_matrix, projection_matrix).
void saveRosCameraInfo(const std::filesystem::path& path, const CameraCalibration& calib,
                       const std::string& cameraName);

}  // namespace mirage
