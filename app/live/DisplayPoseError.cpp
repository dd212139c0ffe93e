#include "app/live/DisplayPoseError.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>

#include "core/Error.h"
#include "tracking/PosePredictor.h"

namespace mirage::app {

namespace {

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    return v[v.size() / 2];
}

// Where the world origin appears with camera pose T_world_camera (pixels).
std::optional<glm::dvec2> originPixel(const CameraIntrinsics& camera, const Pose& T_world_camera) {
    return camera.project(T_world_camera.inverse() * glm::dvec3(0.0));
}

}  // namespace

DisplayPoseError::DisplayPoseError(std::vector<std::optional<Pose>> groundTruth,
                                   std::vector<double> releaseSeconds, CameraIntrinsics camera)
    : truth_(std::move(groundTruth)), release_(std::move(releaseSeconds)), camera_(camera) {
    MR_CHECK(truth_.size() == release_.size(), "DisplayPoseError: one release time per pose");
}

std::optional<Pose> DisplayPoseError::groundTruthAt(double seconds) const {
    if (release_.empty() || !(seconds >= release_.front()) || seconds > release_.back())
        return std::nullopt;
    const size_t i1 =
        size_t(std::upper_bound(release_.begin(), release_.end(), seconds) - release_.begin());
    if (i1 >= release_.size()) return truth_.back();  // exactly the last frame's time
    const size_t i0 = i1 - 1;
    if (!truth_[i0] || !truth_[i1]) return std::nullopt;
    const double span = release_[i1] - release_[i0];
    if (!(span > 0)) return truth_[i0];
    const tracking::PoseVelocity v = tracking::velocityBetween(*truth_[i0], *truth_[i1], span);
    return tracking::extrapolatePose(*truth_[i0], v, seconds - release_[i0]);
}

std::optional<DisplayPoseError::Sample> DisplayPoseError::add(int64_t sequence,
                                                              double captureSeconds,
                                                              double displaySeconds,
                                                              const Pose& shown,
                                                              const Pose& tracked) {
    if (truth_.empty() || sequence < 0) return std::nullopt;
    const size_t k = size_t(sequence) % truth_.size();
    const std::optional<Pose> truth = groundTruthAt(release_[k] + displaySeconds - captureSeconds);
    if (!truth) return std::nullopt;
    const auto pTruth = originPixel(camera_, *truth), pShown = originPixel(camera_, shown),
               pTracked = originPixel(camera_, tracked);
    if (!pTruth || !pShown || !pTracked) return std::nullopt;
    Sample s;
    s.shownPx = glm::length(*pShown - *pTruth);
    s.trackedPx = glm::length(*pTracked - *pTruth);
    s.shownMm = 1e3 * glm::length(shown.translation - truth->translation);
    s.trackedMm = 1e3 * glm::length(tracked.translation - truth->translation);
    samples_.push_back(s);
    return s;
}

std::string DisplayPoseError::summary() const {
    if (samples_.empty()) return "";
    std::vector<double> sp, tp, sm, tm;
    for (const Sample& s : samples_) {
        sp.push_back(s.shownPx);
        tp.push_back(s.trackedPx);
        sm.push_back(s.shownMm);
        tm.push_back(s.trackedMm);
    }
    return cv::format(
        "median %.1f px (%.1f mm) as shown, %.1f px (%.1f mm) without prediction, over %d "
        "frames",
        median(sp), median(sm), median(tp), median(tm), frames());
}

}  // namespace mirage::app
