#pragma once
// Per-frame CSV of tracking results and the run's summary (`mirage track`, docs/tracking.md).
//
// CSV columns (one row per frame, header first; poses are T_world_camera as tx,ty,tz,qw,qx,qy,qz,
// metres, OpenCV camera axes, glTF world):
//   frame,t,state,reason,tx,ty,tz,qw,qx,qy,qz,tags,rms_px,
//   raw_tx,raw_ty,raw_tz,raw_qw,raw_qx,raw_qy,raw_qz,std_rot_deg,std_pos_m,alt_rms_px,
//   detect_ms,pose_ms,gt_rot_err_deg,gt_pos_err_m,mode,feature_ms,landmarks,feature_inliers
// tx..qz is the filtered pose (the raw one with filtering off), raw_* the single-frame estimate.
// Non-ok rows leave the pose columns empty; uncertain rows fill raw_*, std_* and alt_rms_px. `tags`
// lists the used tag ids separated by spaces. mode: what made the pose ("board", "board+features",
// "features only"; docs/tracking.md, "Extended tracking"); feature_ms the natural features' cost,
// landmarks those tracked into the frame, feature_inliers those in the pose (0: none tried).
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "core/math/Pose.h"
#include "tracking/Tracker.h"

namespace mirage::tracking {

struct ErrorStats {
    int count = 0;
    double median = 0, p95 = 0, max = 0;
};
ErrorStats errorStats(std::vector<double> values);

class TrackingReport {
public:
    // Opens the CSV (throws FileError if it cannot be written). boardCentre: world point whose
    // distance to the camera normalises translation errors (percent of distance).
    TrackingReport(const std::filesystem::path& csvPath, glm::dvec3 boardCentre);

    void add(int frameIndex, const TrackedFrame& f, const std::optional<Pose>& groundTruth,
             double decodeMs);
    void addUnreadable(int count) { unreadable_ += count; }
    // A frame whose image is lost (damaged or missing bytes): its row says lost with `lost`'s
    // reason (from Tracker::markLost) and it counts as unreadable, not as a tracked frame.
    void addUnreadableFrame(int frameIndex, const TrackedFrame& lost);
    // Flushes and closes the CSV; throws FileError if any write failed (e.g. the disk is full).
    void close();

    // Human-readable summary (several lines).
    std::string summary() const;
    int frames() const { return frames_; }
    int unreadable() const { return unreadable_; }  // frames reported lost for their input
    int okFrames() const { return stateCount_[0]; }
    // ok frames whose pose is off by more than 2 degrees or 2 % of the distance (needs truth).
    int wrongButOk() const { return wrongOk_; }
    ErrorStats rotationErrorDeg() const { return errorStats(rotErrDeg_); }
    ErrorStats translationErrorRel() const { return errorStats(posErrRel_); }
    // Error of the ok poses not from the board alone against the time since the last ok board
    // pose (needs truth): the drift of extended tracking.
    struct DriftSample {
        double secondsWithoutBoard, rotErrDeg, posErrRel;
    };
    const std::vector<DriftSample>& drift() const { return drift_; }

private:
    std::ofstream csv_;
    std::filesystem::path path_;
    glm::dvec3 boardCentre_;
    int frames_ = 0, withTags_ = 0, unreadable_ = 0, wrongOk_ = 0;
    int tagTracked_ = 0, trackFallbacks_ = 0;      // frames from the tracking mode / its fallbacks
    int boardAndFeatures_ = 0, featuresOnly_ = 0;  // ok frames by mode
    std::optional<double> lastBoardT_;
    std::vector<DriftSample> drift_;
    std::array<int, 7> stateCount_{};  // per TrackingState
    std::vector<double> rms_, decodeMs_, detectMs_, poseMs_, filterMs_, featureMs_;
    std::vector<double> rotErrDeg_, posErrM_, posErrRel_;              // raw estimate vs truth
    std::vector<double> rotErrFiltDeg_, posErrFiltM_, posErrFiltRel_;  // filtered vs truth
};

}  // namespace mirage::tracking
