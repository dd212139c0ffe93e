#pragma once
// Extrinsic calibration: where a camera (typically the fish-eye environment camera) sits
// relative to the main camera, or relative to the world board. Both cameras' intrinsics are
// known (calibrated first, each with its own model, so a pinhole main camera and a fish-eye
// camera combine; cv::stereoCalibrate needs one model for both).
//
// Relative to the main camera: from N simultaneous view pairs of the same board, each pair gives
// T_main_camera_i = T_main_board_i * (T_camera_board_i)^-1 (board poses from PnP on undistorted
// points). Their mean (rotations: normalised sum of sign-aligned quaternions, the chordal L2
// mean; translations: arithmetic mean) starts a joint Levenberg-Marquardt refinement of
// T_camera_main and every pair's board pose over both cameras' reprojection errors (intrinsics
// fixed; core/math/LevenbergMarquardt.h), whose covariance gives the reported 1-sigma uncertainty.
// Pairs whose pose is an outlier (rotation or translation off the first mean by more than 3x the
// median deviation, and more than 1 degree / 10 mm) are dropped.
//
// Frames: camera frames are OpenCV's (+X right, +Y down, +Z forward), metres. T_a_b maps points
// from frame b into frame a.
#include <string>
#include <vector>

#include "calibration/CalibrationTarget.h"
#include "calibration/Calibrator.h"
#include "core/camera/CameraModel.h"
#include "core/math/LevenbergMarquardt.h"
#include "core/math/Pose.h"

namespace mirage::calib {

struct StereoExtrinsics {
    Pose T_main_camera;
    int pairCount = 0;                 // pairs used
    std::vector<std::string> skipped;  // "name: reason"
    // 1-sigma uncertainty of the refined pose: norm of the rotation vector's deviations
    // (degrees) and of the translation's (metres).
    double rotationStdDeg = 0, translationStdM = 0;
    double rotationSpreadDeg = 0;   // RMS angle of the per-pair rotations about the mean
    double translationSpreadM = 0;  // RMS distance of the per-pair translations to the mean
    // Board corners seen by the main camera carried into this camera through T_main_camera:
    // RMS distance to where this camera saw them (pixels). Small = consistent.
    double transferRmsPx = 0;
};

// Pairs are views[i] of both cameras (taken at the same moment); a pair with fewer than 4 points
// in either view is skipped. Throws mirage::Error if no pair is usable.
StereoExtrinsics estimateStereoExtrinsics(const CameraIntrinsics& main,
                                          const std::vector<CalibrationView>& mainViews,
                                          const CameraIntrinsics& camera,
                                          const std::vector<CalibrationView>& cameraViews);

// Reads both input lists (paired by order), detects the target in each and estimates.
// Throws mirage::Error if the lists differ in length or no pair has the board in both.
StereoExtrinsics extrinsicsFromPairedInputs(const CameraIntrinsics& main,
                                            const std::vector<std::string>& mainInputs,
                                            const CameraIntrinsics& camera,
                                            const std::vector<std::string>& cameraInputs,
                                            const CalibrationTarget& target);

struct WorldPose {
    Pose T_world_camera;  // world = the board file's world (a chessboard's own frame)
    double rmsPx = 0;
};

// The joint refinement above as a least-squares problem (core/math/LevenbergMarquardt.h).
// State and step: rvec, tvec of T_camera_main, then rvec, tvec of each pair's T_main_board_i.
// Residuals per pair: the main view's corners, then this camera's (projected - observed, pixels).
// Analytic Jacobian. The problem refers to the arguments, which must outlive it.
lm::Problem stereoLeastSquares(const CameraIntrinsics& main, const CameraIntrinsics& camera,
                               const std::vector<const CalibrationView*>& mainViews,
                               const std::vector<const CalibrationView*>& cameraViews);

// Pose of a camera in the world from one image with the board at its world placement.
WorldPose poseFromWorldBoard(const CameraIntrinsics& camera, const std::string& imagePath,
                             const CalibrationTarget& target);

std::string formatExtrinsics(const StereoExtrinsics& e);

// OpenCV pose (Rodrigues, translation) <-> mirage Pose.
Pose poseFromCv(const cv::Vec3d& rvec, const cv::Vec3d& tvec);

}  // namespace mirage::calib
