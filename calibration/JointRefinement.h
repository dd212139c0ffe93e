#pragma once
// Joint Levenberg-Marquardt refinement of the intrinsics and every view's board pose, and the
// covariance of the intrinsics at the optimum. Used by the Calibrator:
//  - for the fish-eye model after cv::fisheye::calibrate, whose alternating scheme (intrinsics
//    step, then each view's pose re-estimated on its own) can stall at its initial guess when a
//    view is steeply tilted or far off axis; the joint step minimises the same reprojection error
//    over all parameters at once and only accepts steps that lower it;
//  - for both models' standard deviations: Cov = (J^T J)^-1 * sigma^2, J the Jacobian of all
//    residuals (pixels) w.r.t. all free parameters (intrinsics + 6 per view), sigma^2 =
//    sum(r^2) / (2N - P). The same formula as calibrateCameraExtended's, computed here because
//    cv::fisheye reports none.
// The solver and the covariance are core/math/LevenbergMarquardt.h's. Jacobians come from
// cv::projectPoints / cv::fisheye::projectPoints (analytic).
#include <vector>

#include <opencv2/core.hpp>

#include "calibration/Calibrator.h"
#include "core/math/LevenbergMarquardt.h"

namespace mirage::calib {

struct JointProblem {
    std::vector<const CalibrationView*> views;
    CameraIntrinsics intrinsics;          // fx fy cx cy + distortion (5 pinhole, 4 fish-eye)
    std::vector<cv::Vec3d> rvecs, tvecs;  // T_camera_board per view
    std::vector<bool> fixedIntrinsics;    // per intrinsic parameter (8 or 9); empty = all free
    // Per view: its residuals are multiplied by this (the square root of the view's weight in
    // the sum of squares; a view with twice the noise gets 0.5). Empty = all 1.
    std::vector<double> viewScales;

    int intrinsicCount() const;
    double cost() const;  // sum of squared residuals (pixels^2), +inf if not finite
};

// Intrinsic parameter i in the order of the standard deviations below: fx fy cx cy, then the
// distortion coefficients (0 where the model has fewer).
double intrinsicParameter(const CameraIntrinsics& intrinsics, int i);

// Runs LM until converged or maxIterations; returns the final RMS (pixels per point).
double refineJointly(JointProblem& problem, int maxIterations);

// Covariance of the intrinsics (8x8 or 9x9, CV_64F, order fx fy cx cy distortion..., 0 rows and
// columns for fixed ones), or an empty matrix when the normal equations are singular.
cv::Mat intrinsicCovariance(const JointProblem& problem);

// 1-sigma standard deviations of the intrinsics (fx fy cx cy distortion...), 0 for fixed ones,
// +inf for all when the normal equations are singular (an unobservable parameter).
std::vector<double> intrinsicStdDeviations(const JointProblem& problem);

// The problem for the solver. State and step: the free intrinsics (in the order fx fy cx cy
// distortion...), then rvec, tvec of each view. Residuals: projected - observed pixels, x then y
// per point, view by view. The problem refers to `problem`, which must outlive it.
lm::Problem leastSquares(const JointProblem& problem);
std::vector<double> stateOf(const JointProblem& problem);
void setState(JointProblem& problem, const std::vector<double>& x);

// Residuals (projected - observed, x then y per point) of board points seen in `view` through
// `intrinsics` at the board pose (rvec, tvec) = T_camera_board, with their Jacobians with respect
// to the intrinsics (2n x 8 or 9, in the order fx fy cx cy distortion...) and the pose (2n x 6,
// rvec then tvec). Analytic, from OpenCV's projection functions.
void boardResiduals(const CalibrationView& view, const CameraIntrinsics& intrinsics,
                    const cv::Vec3d& rvec, const cv::Vec3d& tvec, std::vector<double>& residuals,
                    cv::Mat* intrinsicsJacobian = nullptr, cv::Mat* poseJacobian = nullptr);

}  // namespace mirage::calib
