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

// Mean image distance (pixels) between where two camera poses T_world_camera show four points
// 10 cm around the world origin on its XZ plane (the board's plane in the bundled scenes, where
// the virtual objects stand; not the origin alone, at which a stand-in's camera may be aimed, so
// that every pose shows it at the image centre). nullopt when a point is behind a camera.
std::optional<double> imageOffset(const CameraIntrinsics& camera, const Pose& a, const Pose& b) {
    const Pose aInv = a.inverse(), bInv = b.inverse();
    double sum = 0;
    for (const glm::dvec3 p : {glm::dvec3(0.1, 0, 0.1), glm::dvec3(-0.1, 0, 0.1),
                               glm::dvec3(0.1, 0, -0.1), glm::dvec3(-0.1, 0, -0.1)}) {
        const auto pa = camera.project(aInv * p), pb = camera.project(bInv * p);
        if (!pa || !pb) return std::nullopt;
        sum += glm::length(*pa - *pb);
    }
    return sum / 4;
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
    const auto shownPx = imageOffset(camera_, shown, *truth),
               trackedPx = imageOffset(camera_, tracked, *truth);
    if (!shownPx || !trackedPx) return std::nullopt;
    Sample s;
    s.shownPx = *shownPx;
    s.trackedPx = *trackedPx;
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
