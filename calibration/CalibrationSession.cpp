#include "calibration/CalibrationSession.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"

namespace mirage::calib {

const char* captureDecisionName(CaptureDecision d) {
    switch (d) {
        case CaptureDecision::NoBoard:
            return "no board";
        case CaptureDecision::Moving:
            return "moving";
        case CaptureDecision::Blurred:
            return "blurred";
        case CaptureDecision::Similar:
            return "similar to a captured view";
        case CaptureDecision::Captured:
            return "captured";
        case CaptureDecision::Held:
            return "captured; move the board";
    }
    return "?";
}

double laplacianVariance(const cv::Mat& grey, const cv::Rect& roi) {
    const cv::Rect r = roi & cv::Rect(0, 0, grey.cols, grey.rows);
    if (r.width < 3 || r.height < 3) return 0;
    cv::Mat lap;
    cv::Laplacian(grey(r), lap, CV_64F);
    cv::Scalar mean, stddev;
    cv::meanStdDev(lap, mean, stddev);
    return stddev[0] * stddev[0];
}

double meanCornerMotion(const CalibrationView& a, const CalibrationView& b) {
    double sum = 0;
    int n = 0;
    size_t j = 0;
    for (size_t i = 0; i < a.boardPoints.size(); ++i) {
        // Both lists keep the target's order, so a forward scan finds the matches.
        size_t k = j;
        while (k < b.boardPoints.size() && b.boardPoints[k] != a.boardPoints[i]) ++k;
        if (k == b.boardPoints.size()) continue;
        sum += cv::norm(a.imagePoints[i] - b.imagePoints[k]);
        ++n;
        j = k + 1;
    }
    return n >= 4 ? sum / n : -1;
}

CalibrationSession::CalibrationSession(CalibrationTarget target, cv::Size imageSize,
                                       SessionOptions options)
    : target_(std::move(target)),
      size_(imageSize),
      options_(options),
      coverage_(imageSize),
      tilts_(15.0) {}

CalibrationSession::ViewSignature CalibrationSession::signatureOf(
    const std::vector<cv::Point2f>& corners, double tiltDeg, double directionDeg) const {
    ViewSignature s;
    cv::Point2f c(0, 0);
    for (const auto& p : corners) c += p;
    s.centroid = c * (1.0f / float(std::max<size_t>(1, corners.size())));
    std::vector<cv::Point2f> hull;
    cv::convexHull(corners, hull);
    s.area = cv::contourArea(hull);
    s.tiltDeg = tiltDeg;
    s.directionDeg = directionDeg;
    return s;
}

bool CalibrationSession::isNovel(const ViewSignature& s) const {
    const double diag = std::hypot(size_.width, size_.height);
    for (const auto& o : signatures_) {
        const bool samePlace = cv::norm(s.centroid - o.centroid) < options_.minCentroidShift * diag;
        const bool sameScale =
            std::abs(s.area - o.area) < options_.minScaleChange * std::max(o.area, 1.0);
        // Tilt difference as the angle between the two normals' (tilt, direction) pairs.
        const double t1 = s.tiltDeg * CV_PI / 180, t2 = o.tiltDeg * CV_PI / 180;
        const double d1 = s.directionDeg * CV_PI / 180, d2 = o.directionDeg * CV_PI / 180;
        const cv::Vec3d n1(std::sin(t1) * std::cos(d1), std::sin(t1) * std::sin(d1), std::cos(t1));
        const cv::Vec3d n2(std::sin(t2) * std::cos(d2), std::sin(t2) * std::sin(d2), std::cos(t2));
        const double dTilt = std::acos(std::clamp(n1.dot(n2), -1.0, 1.0)) * 180 / CV_PI;
        if (samePlace && sameScale && dTilt < options_.minTiltChangeDeg) return false;
    }
    return true;
}

CameraIntrinsics CalibrationSession::currentIntrinsics() const {
    if (result_) return result_->calibration.intrinsics;
    // Before the first calibration: a plausible guess (a fish-eye's image diagonal spanning
    // 180 degrees); tilts and the coverage by angle are only needed roughly here.
    CameraIntrinsics in;
    in.width = size_.width;
    in.height = size_.height;
    in.model = options_.calibration.model;
    const double diag = std::hypot(size_.width, size_.height);
    in.fx = in.fy = in.model == DistortionModel::KannalaBrandt ? diag / CV_PI : 0.9 * diag;
    in.cx = (size_.width - 1) / 2.0;
    in.cy = (size_.height - 1) / 2.0;
    in.distortion.assign(in.model == DistortionModel::KannalaBrandt ? 4 : 5, 0.0);
    return in;
}

void CalibrationSession::estimateTilt(const CalibrationView& view, double& tiltDeg,
                                      double& directionDeg) const {
    const CameraIntrinsics in = currentIntrinsics();
    cv::Vec3d rvec, tvec;
    tiltDeg = directionDeg = 0;
    if (estimateBoardPose(view, in, rvec, tvec)) boardTilt(rvec, tiltDeg, directionDeg);
}

FrameReport CalibrationSession::processFrame(const cv::Mat& image, const std::string& name) {
    if (image.size() != size_)
        throw Error(fmt::format("{}: frame is {}x{} but the session is {}x{}", name, image.cols,
                                image.rows, size_.width, size_.height));
    cv::Mat grey = image;
    if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
    FrameReport rep;
    auto d = target_.detect(grey, name);
    if (!d.found) {
        previousView_ = {};
        stillCount_ = 0;
        heldSinceCapture_ = false;
        return rep;
    }
    rep.boardFound = true;
    rep.view = d.view;
    const auto& corners = rep.view.imagePoints;
    rep.motionPx = meanCornerMotion(previousView_, rep.view);
    previousView_ = rep.view;
    if (rep.motionPx >= 0 && rep.motionPx < options_.stillMotionPx) {
        ++stillCount_;
    } else {
        stillCount_ = 0;
        heldSinceCapture_ = false;
    }
    rep.sharpness = laplacianVariance(grey, cv::boundingRect(corners));
    // The reference decays (~30 frames) so a change of scene or lighting is followed.
    recentSharpest_ = std::max(rep.sharpness, recentSharpest_ * 0.97);
    estimateTilt(d.view, rep.tiltDeg, rep.tiltDirectionDeg);

    if (stillCount_ < options_.stillFrames) {
        rep.decision = CaptureDecision::Moving;
    } else if (heldSinceCapture_) {
        rep.decision = CaptureDecision::Held;
    } else if (rep.sharpness <
               std::max(options_.minSharpness, options_.blurFraction * recentSharpest_)) {
        rep.decision = CaptureDecision::Blurred;
    } else if (!isNovel(signatureOf(corners, rep.tiltDeg, rep.tiltDirectionDeg))) {
        rep.decision = CaptureDecision::Similar;
    } else {
        addView(std::move(d.view));
        heldSinceCapture_ = true;
        rep.decision = CaptureDecision::Captured;
        rep.recalibrated = true;
    }
    return rep;
}

void CalibrationSession::addView(CalibrationView view) {
    double tilt, dir;
    estimateTilt(view, tilt, dir);
    signatures_.push_back(signatureOf(view.imagePoints, tilt, dir));
    views_.push_back(std::move(view));
    recalibrate();
}

void CalibrationSession::dropView(size_t index) {
    if (index >= views_.size()) return;
    views_.erase(views_.begin() + long(index));
    signatures_.erase(signatures_.begin() + long(index));
    recalibrate();
}

void CalibrationSession::recalibrate() {
    result_.reset();
    calibrationError_.clear();
    if (int(views_.size()) >= options_.calibration.minViews) {
        try {
            result_ = calibrate(views_, size_, options_.calibration);
        } catch (const Error& e) {
            calibrationError_ = e.what();
        }
    }
    rebuildCoverage();
    state_ = unmetTargets().empty() ? State::Done : State::Collecting;
}

void CalibrationSession::rebuildCoverage() {
    coverage_.clear();
    tilts_.clear();
    // A fish-eye's coverage is counted in angles off-axis through the current estimate.
    if (options_.calibration.model == DistortionModel::KannalaBrandt)
        coverage_.setAngularLens(currentIntrinsics());
    for (size_t i = 0; i < views_.size(); ++i) {
        const bool rejected = result_ && result_->views[i].rejected;
        if (rejected) continue;
        coverage_.add(views_[i].imagePoints);
        // Calibrated tilts where available (the estimate uses the fitted intrinsics).
        if (result_)
            tilts_.add(result_->views[i].tiltDeg, result_->views[i].tiltDirectionDeg);
        else
            tilts_.add(signatures_[i].tiltDeg, signatures_[i].directionDeg);
    }
}

std::vector<std::string> CalibrationSession::unmetTargets() const {
    std::vector<std::string> unmet;
    const int used = result_ ? result_->usedViewCount() : int(views_.size());
    if (used < options_.doneMinViews)
        unmet.push_back(fmt::format("views {}/{}", used, options_.doneMinViews));
    // Fish-eye: the rings off-axis with no corner yet (from the nominal lens before the first
    // calibration, so the wizard says where to go from the first capture on).
    for (const auto& ring : coverage_.missingRings()) unmet.push_back(ring);
    if (!result_) {
        unmet.push_back(calibrationError_.empty() ? "no calibration yet"
                                                  : "calibration failed: " + calibrationError_);
        return unmet;
    }
    const auto& c = result_->calibration;
    if (!c.reliable) unmet.push_back("unreliable: " + c.unreliableReason);
    const double relF = result_->relativeFocalStd();
    if (!(relF <= options_.doneRelativeFocalStd))
        unmet.push_back(fmt::format("focal std {:.2f}% > {:.2f}%", 100 * relF,
                                    100 * options_.doneRelativeFocalStd));
    const double pp = c.stdDeviations.size() >= 4 ? std::max(c.stdDeviations[2], c.stdDeviations[3])
                                                  : std::numeric_limits<double>::infinity();
    if (!(pp <= options_.donePrincipalPointStdPx))
        unmet.push_back(fmt::format("principal point std {:.2f} px > {:.2f} px", pp,
                                    options_.donePrincipalPointStdPx));
    // A fish-eye's distortion is decided toward the rim: say how far off-axis the corners reach.
    const bool fisheye = c.intrinsics.model == DistortionModel::KannalaBrandt;
    if (coverage_.coveredFraction() < options_.doneCoverage)
        unmet.push_back(
            fisheye
                ? fmt::format("coverage {:.0f}% of the off-axis rings and sectors < {:.0f}%: "
                              "corners reach {:.0f} deg off-axis; bring the board toward the rim",
                              100 * coverage_.coveredFraction(), 100 * options_.doneCoverage,
                              c.reachDeg)
                : fmt::format("coverage {:.0f}% < {:.0f}%", 100 * coverage_.coveredFraction(),
                              100 * options_.doneCoverage));
    return unmet;
}

std::string CalibrationSession::advice() const {
    if (views_.empty())
        return "Hold the board in front of the camera and keep it still until it is captured.";
    if (state_ == State::Done)
        return "Done: the uncertainty is below the targets. Save, or keep adding views.";
    if (result_) {
        for (const auto& v : result_->views)
            if (v.rejected)
                return fmt::format(
                    "View '{}' was dropped as an outlier ({}); check for motion "
                    "blur or a bent board.",
                    v.name, v.rejectReason);
    }
    if (tilts_.maxTiltDeg() < 15.0)
        return "Tilt the board about 30 degrees (turn it left/right, up/down): tilted views are "
               "what pin down the focal length.";
    if (coverage_.coveredFraction() < options_.doneCoverage) {
        std::string region;
        coverage_.emptiestRegion(region);
        if (coverage_.angular())
            return fmt::format(
                "Move the board to {} of the image: distortion is only known "
                "where corners have been.",
                region);
        return fmt::format(
            "Move the board to the {} of the image: distortion is only known "
            "where corners have been.",
            region);
    }
    if (const auto bin = tilts_.missingBin(); bin != TiltCoverage::BinCount)
        return fmt::format("Tilt the board so it is {} (about 30 degrees).",
                           TiltCoverage::binName(bin));
    std::string region;
    coverage_.emptiestRegion(region);
    if (coverage_.angular())
        return fmt::format(
            "Add tilted views at {}, at different distances, until the uncertainty drops.", region);
    return fmt::format(
        "Add tilted views near the {} of the image, at different distances, "
        "until the uncertainty drops.",
        region);
}

}  // namespace mirage::calib
