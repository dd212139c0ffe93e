#pragma once
// The calibration wizard's logic, free of any UI (the window in app/wizard/ only displays it).
// Frames go in one by one; the session detects the board, decides whether to capture the frame
// as a view (automatic capture when the board is still and sharp and the view adds something),
// recalibrates after each capture, tracks coverage and tilts, gives advice where to put the board
// next, and says when the uncertainty is low enough to stop.
//
// State machine:  Collecting --(enough views, reliable, uncertainty below the targets,
//                 coverage reached)--> Done.  Done falls back to Collecting if a later capture
//                 (or a dropped view) makes it unmet again. Capturing continues in Done (more
//                 views only help); the user saves whenever they like.
//
// Per frame decision (FrameReport::decision), in this order:
//   NoBoard     the board is not detected;
//   Moving      mean corner motion since the previous frame > stillMotionPx (pixels/frame), or
//               the board has not been still for stillFrames consecutive frames yet;
//   Blurred     Laplacian variance over the board's bounding box < blurFraction x the sharpest
//               recent frame (or < minSharpness): out of focus or motion blur;
//   Similar     a captured view already has nearly the same place, size and tilt;
//   Captured    added as a view;
//   Held        still, already captured while it stays still (move the board to capture again).
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calibration/CalibrationTarget.h"
#include "calibration/Calibrator.h"
#include "calibration/CoverageMap.h"

namespace mirage::calib {

struct SessionOptions {
    CalibrationOptions calibration;
    // Auto-capture.
    double stillMotionPx = 0.8;  // mean corner motion per frame below which the board is still
    int stillFrames = 3;         // consecutive still frames needed
    double blurFraction = 0.55;  // of the recent sharpest Laplacian variance
    double minSharpness = 15.0;  // Laplacian variance floor (8-bit grey)
    // Novelty: a new view must differ from every captured one by one of these.
    double minCentroidShift = 0.10;  // fraction of the image diagonal
    double minScaleChange = 0.20;    // relative change of the board's image area
    double minTiltChangeDeg = 10.0;
    // Done when all hold.
    int doneMinViews = 10;
    double doneRelativeFocalStd = 0.004;  // std(f) / f
    double donePrincipalPointStdPx = 2.0;
    double doneCoverage = 0.55;  // fraction of coverage cells with a corner
};

enum class CaptureDecision { NoBoard, Moving, Blurred, Similar, Captured, Held };
const char* captureDecisionName(CaptureDecision d);

struct FrameReport {
    bool boardFound = false;
    CalibrationView view;  // the detection (imagePoints in pixels), when found
    CaptureDecision decision = CaptureDecision::NoBoard;
    double motionPx = -1;  // mean corner motion since the previous frame, < 0 if unknown
    double sharpness = 0;  // Laplacian variance over the board
    double tiltDeg = 0, tiltDirectionDeg = 0;  // estimated with the current (or guessed) intrinsics
    bool recalibrated = false;
};

class CalibrationSession {
public:
    enum class State { Collecting, Done };

    CalibrationSession(CalibrationTarget target, cv::Size imageSize, SessionOptions options);

    // One frame (8-bit BGR or grey, the same size as imageSize). Throws mirage::Error on a frame
    // of another size.
    FrameReport processFrame(const cv::Mat& image, const std::string& name);
    // Adds a view regardless of the capture gate (a "capture now" button, or tests).
    void addView(CalibrationView view);
    // Removes captured view i and recalibrates.
    void dropView(size_t index);

    State state() const { return state_; }
    const std::vector<CalibrationView>& views() const { return views_; }
    // The latest calibration (after at least calibration.minViews captures), if it succeeded.
    const std::optional<CalibrationResult>& result() const { return result_; }
    const std::string& calibrationError() const { return calibrationError_; }
    const CoverageMap& coverage() const { return coverage_; }
    const TiltCoverage& tilts() const { return tilts_; }
    const CalibrationTarget& target() const { return target_; }
    cv::Size imageSize() const { return size_; }
    // One sentence: what to do next.
    std::string advice() const;
    // Which "done" targets are not met yet (empty when Done).
    std::vector<std::string> unmetTargets() const;

private:
    struct ViewSignature {
        cv::Point2f centroid;
        double area, tiltDeg, directionDeg;
    };
    ViewSignature signatureOf(const std::vector<cv::Point2f>& corners, double tiltDeg,
                              double directionDeg) const;
    bool isNovel(const ViewSignature& s) const;
    // The latest calibration's intrinsics, or a nominal guess of the configured model before one.
    CameraIntrinsics currentIntrinsics() const;
    void estimateTilt(const CalibrationView& view, double& tiltDeg, double& directionDeg) const;
    void recalibrate();
    void rebuildCoverage();

    CalibrationTarget target_;
    cv::Size size_;
    SessionOptions options_;
    State state_ = State::Collecting;
    std::vector<CalibrationView> views_;
    std::vector<ViewSignature> signatures_;
    std::optional<CalibrationResult> result_;
    std::string calibrationError_;
    CoverageMap coverage_;
    TiltCoverage tilts_;
    // Capture gate state.
    CalibrationView previousView_;  // the last detection, for the motion between frames
    int stillCount_ = 0;
    bool heldSinceCapture_ = false;
    double recentSharpest_ = 0;
};

// Variance of the Laplacian of an 8-bit grey image over a rectangle: a focus/blur measure.
double laplacianVariance(const cv::Mat& grey, const cv::Rect& roi);
// Mean image distance (pixels) between the corners of the same board points in two detections
// (matched by board point: the views may hold different subsets, in the target's order); < 0 if
// they share fewer than 4 board points.
double meanCornerMotion(const CalibrationView& a, const CalibrationView& b);

}  // namespace mirage::calib
