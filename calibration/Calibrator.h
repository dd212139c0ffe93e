#pragma once
// Intrinsic calibration of one camera from views of a planar board (docs/calibration.md).
//
// Models (core/camera/CameraModel.h):
//  - pinhole + Brown-Conrady (k1, k2, p1, p2, k3): cv::calibrateCameraExtended, which also gives
//    per-parameter standard deviations and per-view errors;
//  - OpenCV fisheye (Kannala-Brandt k1..k4): cv::fisheye::calibrate with
//    CALIB_RECOMPUTE_EXTRINSIC | CALIB_FIX_SKEW. cv::fisheye reports no uncertainty, so the
//    standard deviations are computed here the way calibrateCameraExtended does it for the
//    pinhole model: Cov = (J^T J)^-1 * sigma^2 with J the Jacobian of all residuals (pixels) with
//    respect to all parameters (intrinsics + 6 per view) and sigma^2 = sum(r^2) / (2N - P).
//
// Views whose RMS error is far above the median are dropped one at a time (worst first) with a
// recalibration after each drop. Then single corners: a corner whose residual lies far outside
// its view's noise (cornerOutlierSigmas x the view's noise and at least cornerOutlierMinPx) is
// dropped, counted and listed, and the rest re-solved, until none is left; finally views noisier
// than the median view are down-weighted by their measured noise (weight (median / noise)^2) so a
// blurred view cannot pull the model the way a sharp one does. The result is marked unreliable,
// with the reason, when the data cannot pin the parameters down: too few views, all views
// fronto-parallel (the focal length is then unobservable: the board's image only scales with
// f/distance), or standard deviations that are large relative to the values. Callers must never
// present an unreliable result as a confident number (the calibration file carries `reliable:
// false` and the reason).
//
// Units: pixels for image points, errors and standard deviations of fx, fy, cx, cy; metres for
// board points; degrees for tilts. Board points lie in the board's z = 0 plane.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/camera/CalibrationFile.h"
#include "core/camera/CameraModel.h"

namespace mirage::calib {

// One image's detected board corners and the board points they correspond to.
struct CalibrationView {
    std::string name;                      // file name or "frame N": used in reports
    std::vector<cv::Point2f> imagePoints;  // pixels, (0,0) = centre of the top-left pixel
    std::vector<cv::Point3f> boardPoints;  // metres, board frame (z = 0)
    // Which detector found the board ("classic", "sector-based", "tags", "charuco"; empty when
    // not from a detector), and how many of its corners were left out because their sub-pixel
    // refinement did not converge.
    std::string detector;
    int unrefinedCorners = 0;
};

struct CalibrationOptions {
    DistortionModel model = DistortionModel::BrownConrady;
    // Pinhole only: keep k3 at 0 (fits k1, k2, p1, p2), for narrow-angle lenses and datasets
    // calibrated that way (OpenCV's calib1 reference uses it).
    bool fixK3 = false;

    // Outlier views: a view is dropped when its RMS error exceeds outlierFactor * median AND
    // outlierMinErrorPx (so a clean set with median 0.1 px does not lose a 0.35 px view).
    double outlierFactor = 3.0;
    double outlierMinErrorPx = 0.5;
    double maxRejectedFraction = 0.3;  // never drop more than this share of the views

    // Outlier corners: residual (pixels, length of the 2D error) above cornerOutlierSigmas x the
    // view's noise (per coordinate, from the median residual) and above cornerOutlierMinPx. At
    // most maxRejectedCornerFraction of a view's corners are dropped (more means the view itself
    // is bad, which the view rule handles).
    double cornerOutlierSigmas = 5.0;
    double cornerOutlierMinPx = 0.3;
    double maxRejectedCornerFraction = 0.2;
    // Views noisier than the median view by more than this factor are down-weighted.
    bool weightViewsByNoise = true;

    // Reliability. Fewer views than this, or a largest board tilt below minMaxTiltDeg, or a
    // relative focal-length standard deviation above maxRelativeFocalStd, or a principal-point
    // standard deviation above maxPrincipalPointStd (fraction of the image width) marks the
    // result unreliable.
    int minViews = 3;
    double minMaxTiltDeg = 10.0;
    double maxRelativeFocalStd = 0.02;
    double maxPrincipalPointStd = 0.02;

    int maxIterations = 100;
};

// A corner dropped as an outlier.
struct DroppedCorner {
    cv::Point3f boardPoint;  // metres, board frame
    cv::Point2f imagePoint;  // pixels, as detected
    double residualPx = 0;   // length of its reprojection error when dropped
};

// What happened to one input view.
struct ViewResult {
    std::string name;
    std::string detector;  // CalibrationView::detector
    int pointCount = 0;    // corners used (after dropped outliers)
    int unrefinedCorners = 0;
    std::vector<DroppedCorner> droppedCorners;
    // Measured noise of this view's corners: per-coordinate standard deviation (pixels) from the
    // median residual length (median / 1.1774, a 2D Gaussian's), and its weight in the fit.
    double noisePx = -1;
    double weight = 1;
    double rmsPx = -1;      // RMS reprojection error of this view (pixels), < 0 if not computed
    bool rejected = false;  // dropped as an outlier (or unusable)
    std::string rejectReason;
    // Board pose in the camera: T_camera_board as Rodrigues vector + translation (metres).
    cv::Vec3d rvec, tvec;
    // Board tilt (degrees; 0 = facing the camera) and the direction of the tilt in the image
    // (degrees, atan2 of the normal's y and x). Pinhole: against the optical axis (a board
    // parallel to the image plane leaves the focal length unobservable). Fish-eye: against the
    // line of sight to the board's centre, so a board facing the camera at the rim reads 0.
    double tiltDeg = 0, tiltDirectionDeg = 0;
    // Largest angle off the optical axis of this view's corners (degrees).
    double maxOffAxisDeg = 0;
};

struct CalibrationResult {
    CameraCalibration calibration;  // intrinsics, RMS, std devs, per-view errors (used views)
    std::vector<std::string> parameterNames;  // matching calibration.stdDeviations
    std::vector<ViewResult> views;            // every input view, input order
    std::vector<std::string> warnings;        // things worth saying that do not make it unreliable
    double maxTiltDeg = 0;                    // over the used views
    int droppedCornerCount = 0;               // over the used views
    // Covariance of the intrinsics (order of parameterNames, CV_64F), empty if singular.
    cv::Mat intrinsicCovariance;

    int usedViewCount() const;
    // Standard deviation of fx / fx (and fy / fy): the relative focal uncertainty, or +inf.
    double relativeFocalStd() const;
};

// Calibrates. Throws mirage::Error if there is nothing to calibrate from (no view with at least
// 4 points after validation) or the solver produces no finite result; the message says why and
// what to do. Otherwise returns a result that is either reliable or says why it is not.
CalibrationResult calibrate(const std::vector<CalibrationView>& views, cv::Size imageSize,
                            const CalibrationOptions& options);

// What goes into the calibration file: the result's calibration, with standard deviations left
// out (and the reason saying so) when some are not finite (an unobservable parameter): the file
// format holds finite numbers only, and such a result is always marked unreliable.
CameraCalibration calibrationForFile(const CalibrationResult& result);

// Parameter names in the order of the standard deviations ("fx", "fy", "cx", "cy", "k1", ...).
std::vector<std::string> parameterNames(DistortionModel model);

// Projects board points with intrinsics and a board pose T_camera_board (either model).
std::vector<cv::Point2f> projectBoardPoints(const std::vector<cv::Point3f>& boardPoints,
                                            const CameraIntrinsics& intrinsics,
                                            const cv::Vec3d& rvec, const cv::Vec3d& tvec);

// Board pose T_camera_board from the view's points with known intrinsics (solvePnP on
// undistorted points, so it works for both models). Returns false if it fails.
bool estimateBoardPose(const CalibrationView& view, const CameraIntrinsics& intrinsics,
                       cv::Vec3d& rvec, cv::Vec3d& tvec);

// Tilt of a board with pose rvec (T_camera_board): degrees off fronto-parallel and direction.
void boardTilt(const cv::Vec3d& rvec, double& tiltDeg, double& directionDeg);
// Tilt against the line of sight from the camera to `boardCentre` (board frame, metres): 0 when
// the board faces the camera wherever it is in the field of view; direction as boardTilt's.
void boardTiltToLineOfSight(const cv::Vec3d& rvec, const cv::Vec3d& tvec,
                            const cv::Point3f& boardCentre, double& tiltDeg, double& directionDeg);

// 1-sigma uncertainty (pixels, the RMS length of the 2D error: sqrt of the trace of the
// projected covariance) of where `intrinsics` project the camera-frame direction `direction`,
// from the intrinsics' covariance. +inf if the covariance is empty.
double projectionStdPx(const CameraIntrinsics& intrinsics, const cv::Mat& covariance,
                       const cv::Vec3d& direction);

cv::Mat cameraMatrix(const CameraIntrinsics& intrinsics);      // 3x3 CV_64F
cv::Mat distortionVector(const CameraIntrinsics& intrinsics);  // 1xN CV_64F

}  // namespace mirage::calib
