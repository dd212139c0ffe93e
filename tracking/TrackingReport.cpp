#include "tracking/TrackingReport.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/Csv.h"
#include "core/Error.h"

namespace mirage::tracking {

ErrorStats errorStats(std::vector<double> v) {
    ErrorStats s;
    s.count = int(v.size());
    if (v.empty()) return s;
    std::sort(v.begin(), v.end());
    auto q = [&](double p) {
        return v[std::min(v.size() - 1, size_t(p * double(v.size() - 1) + 0.5))];
    };
    s.median = q(0.5);
    s.p95 = q(0.95);
    s.max = v.back();
    return s;
}

TrackingReport::TrackingReport(const std::filesystem::path& csvPath, glm::dvec3 boardCentre)
    : path_(csvPath), boardCentre_(boardCentre) {
    csv_.open(csvPath);
    if (!csv_) throw FileError(csvPath.string(), "cannot write the poses CSV");
    csv_ << "frame,t,state,reason,tx,ty,tz,qw,qx,qy,qz,tags,rms_px,"
            "raw_tx,raw_ty,raw_tz,raw_qw,raw_qx,raw_qy,raw_qz,std_rot_deg,std_pos_m,alt_rms_px,"
            "detect_ms,pose_ms,gt_rot_err_deg,gt_pos_err_m,mode,feature_ms,landmarks,"
            "feature_inliers\n";
}

namespace {
std::string poseCols(const std::optional<Pose>& p) {
    if (!p) return ",,,,,,";
    char b[256];
    std::snprintf(b, sizeof b, "%.7f,%.7f,%.7f,%.9f,%.9f,%.9f,%.9f", p->translation.x,
                  p->translation.y, p->translation.z, p->rotation.w, p->rotation.x, p->rotation.y,
                  p->rotation.z);
    return b;
}
}  // namespace

void TrackingReport::add(int frameIndex, const TrackedFrame& f,
                         const std::optional<Pose>& groundTruth, double decodeMs) {
    ++frames_;
    const PoseEstimate& e = f.estimate;
    ++stateCount_[size_t(e.state)];
    if (!e.tagsUsed.empty() || !e.tagsRejected.empty()) ++withTags_;
    tagTracked_ += f.tagTracked;
    trackFallbacks_ += f.tagTrackingTried && !f.tagTracked;
    decodeMs_.push_back(decodeMs);
    detectMs_.push_back(f.detectMs);
    poseMs_.push_back(f.poseMs);
    filterMs_.push_back(f.filterMs);
    featureMs_.push_back(f.featureMs);
    const bool ok = e.state == TrackingState::Ok;
    if (ok && f.mode != TrackingMode::Board) {
        ++(f.mode == TrackingMode::FeaturesOnly ? featuresOnly_ : boardAndFeatures_);
    }
    if (ok && f.mode == TrackingMode::Board) lastBoardT_ = f.t;
    std::string tags;
    for (int id : e.tagsUsed) tags += (tags.empty() ? "" : " ") + std::to_string(id);
    char b[512];
    std::snprintf(b, sizeof b, "%d,%.6f,%s,", frameIndex, f.t, trackingStateName(e.state));
    csv_ << b << csvField(e.reason) << "," << poseCols(ok ? f.filtered : std::nullopt) << ","
         << tags << ",";
    if (ok) {
        rms_.push_back(e.rmsPx);
        std::snprintf(b, sizeof b, "%.4f", e.rmsPx);
        csv_ << b;
    }
    // Uncertain rows keep the raw pose and its uncertainty (for inspection, never as output).
    const bool withRaw = ok || e.state == TrackingState::Uncertain;
    csv_ << "," << poseCols(withRaw ? e.pose : std::nullopt) << ",";
    if (withRaw && e.covariance[0] > 0) {
        const double rotVar = e.covariance[0] + e.covariance[7] + e.covariance[14];
        const double posVar = e.covariance[21] + e.covariance[28] + e.covariance[35];
        std::snprintf(b, sizeof b, "%.5f,%.6f", glm::degrees(std::sqrt(rotVar)), std::sqrt(posVar));
        csv_ << b;
    } else {
        csv_ << ",";
    }
    csv_ << ",";
    if (withRaw && e.alternativeRmsPx >= 0) {
        std::snprintf(b, sizeof b, "%.4f", e.alternativeRmsPx);
        csv_ << b;
    }
    std::snprintf(b, sizeof b, ",%.3f,%.3f,", f.detectMs, f.poseMs);
    csv_ << b;
    // Ground truth comes range-checked from frames.csv (core/session/FramesCsv.h); a value that
    // still overflows the error figures is not compared rather than printed as inf or NaN.
    const bool comparable =
        groundTruth && std::isfinite(glm::length(groundTruth->translation)) &&
        std::isfinite(glm::length(e.pose ? e.pose->translation : glm::dvec3(0)));
    if (ok && comparable) {
        const double rotErr =
            glm::degrees(rotationAngleBetween(e.pose->rotation, groundTruth->rotation));
        const double posErr = glm::length(e.pose->translation - groundTruth->translation);
        const double dist = std::max(1e-9, glm::length(groundTruth->translation - boardCentre_));
        rotErrDeg_.push_back(rotErr);
        posErrM_.push_back(posErr);
        posErrRel_.push_back(posErr / dist);
        if (f.filtered) {
            rotErrFiltDeg_.push_back(
                glm::degrees(rotationAngleBetween(f.filtered->rotation, groundTruth->rotation)));
            const double filtErr = glm::length(f.filtered->translation - groundTruth->translation);
            posErrFiltM_.push_back(filtErr);
            posErrFiltRel_.push_back(filtErr / dist);
        }
        if (rotErr > 2.0 || posErr / dist > 0.02) ++wrongOk_;
        if (f.mode != TrackingMode::Board && lastBoardT_)
            drift_.push_back({f.t - *lastBoardT_, rotErr, posErr / dist});
        std::snprintf(b, sizeof b, "%.5f,%.6f", rotErr, posErr);
        csv_ << b;
    } else {
        csv_ << ",";
    }
    std::snprintf(b, sizeof b, ",%s,%.3f,%d,%d\n", trackingModeName(f.mode), f.featureMs,
                  f.features.landmarks, f.features.inliers);
    csv_ << b;
    csv_.flush();
}

void TrackingReport::addUnreadableFrame(int frameIndex, const TrackedFrame& lost) {
    add(frameIndex, lost, std::nullopt, 0.0);
    // The row is written; the counts move from "tracked, lost" to "unreadable".
    --frames_;
    --stateCount_[size_t(lost.estimate.state)];
    ++unreadable_;
    decodeMs_.pop_back();
    detectMs_.pop_back();
    poseMs_.pop_back();
    filterMs_.pop_back();
    featureMs_.pop_back();
}

void TrackingReport::close() {
    csv_.flush();
    const bool ok = csv_.good();
    csv_.close();
    if (!ok || csv_.fail())
        throw FileError(path_.string(), "writing the poses CSV failed (disk full?)");
}

std::string TrackingReport::summary() const {
    std::string s;
    char b[512];
    const int total = frames_ + unreadable_;
    std::snprintf(b, sizeof b, "frames: %d (%d unreadable, reported lost)\n", total, unreadable_);
    s += b;
    const double denom = std::max(1, total);
    std::snprintf(b, sizeof b, "detection rate (a board tag seen): %.1f %%   ok: %.1f %%\n",
                  100.0 * withTags_ / denom, 100.0 * stateCount_[0] / denom);
    s += b;
    s += "states:";
    for (int i = 0; i < int(stateCount_.size()); ++i) {
        int n = stateCount_[size_t(i)] + (i == int(TrackingState::Lost) ? unreadable_ : 0);
        std::snprintf(b, sizeof b, " %s %d", trackingStateName(TrackingState(i)), n);
        s += b;
    }
    s += "\n";
    std::snprintf(
        b, sizeof b,
        "tracking mode (tags where the predicted pose puts them): %d frames, %d fell back "
        "to the search\n",
        tagTracked_, trackFallbacks_);
    s += b;
    std::snprintf(b, sizeof b,
                  "extended tracking: %d ok frames from board+features, %d from features only; "
                  "features %.2f ms per frame (median)\n",
                  boardAndFeatures_, featuresOnly_, errorStats(featureMs_).median);
    s += b;
    const ErrorStats rms = errorStats(rms_);
    std::snprintf(b, sizeof b, "reprojection RMS (ok frames): median %.3f px, p95 %.3f, max %.3f\n",
                  rms.median, rms.p95, rms.max);
    s += b;
    std::snprintf(b, sizeof b,
                  "ms per frame (median): decode %.2f, detect %.2f, pose %.2f, filter %.3f\n",
                  errorStats(decodeMs_).median, errorStats(detectMs_).median,
                  errorStats(poseMs_).median, errorStats(filterMs_).median);
    s += b;
    if (!rotErrDeg_.empty()) {
        const ErrorStats r = errorStats(rotErrDeg_), t = errorStats(posErrM_),
                         tr = errorStats(posErrRel_);
        std::snprintf(b, sizeof b,
                      "ground truth (%d ok frames), raw: rotation error median %.4f deg, p95 %.4f, "
                      "max %.4f; translation error median %.5f m (%.3f %% of distance), p95 %.5f "
                      "m, max %.5f m (%.3f %%)\n",
                      r.count, r.median, r.p95, r.max, t.median, 100 * tr.median, t.p95, t.max,
                      100 * tr.max);
        s += b;
        if (!rotErrFiltDeg_.empty()) {
            const ErrorStats rf = errorStats(rotErrFiltDeg_), tf = errorStats(posErrFiltM_),
                             tfr = errorStats(posErrFiltRel_);
            std::snprintf(b, sizeof b,
                          "ground truth, filtered: rotation error median %.4f deg, p95 %.4f, "
                          "max %.4f; translation error median %.5f m (%.3f %% of distance), p95 "
                          "%.5f m, max %.5f m (%.3f %%)\n",
                          rf.median, rf.p95, rf.max, tf.median, 100 * tfr.median, tf.p95, tf.max,
                          100 * tfr.max);
            s += b;
        }
        std::snprintf(b, sizeof b, "wrong-but-ok frames (> 2 deg or > 2 %%): %d\n", wrongOk_);
        s += b;
    }
    return s;
}

}  // namespace mirage::tracking
