#include "app/replay/ReplayPoses.h"

#include <filesystem>

#include "core/Log.h"

namespace mirage::app {

ReplayPoses::ReplayPoses(const Session& session, const CameraIntrinsics& camera,
                         const std::string& posesFile, bool groundTruth, bool boardOnly) {
    if (!posesFile.empty()) {
        poses_ = readPosesCsv(posesFile);
        checkPoseFrames(poses_, session, posesFile);
        usePosesFile_ = true;
    } else if (!groundTruth && !session.board.empty() &&
               std::filesystem::exists(session.path(session.board))) {
        tracking::TrackerOptions trackerOptions;
        trackerOptions.features.enabled = !boardOnly;
        tracker_ = std::make_unique<tracking::Tracker>(
            tracking::Board::load(session.path(session.board)), camera, trackerOptions);
        spdlog::info("replay: tracking the camera on {}", session.path(session.board).string());
    } else {
        spdlog::info("replay: camera poses from the session's ground truth (frames.csv){}",
                     groundTruth ? "" : " (the session has no board file to track)");
    }
}

std::optional<PoseRow> ReplayPoses::given(const FrameRecord& rec, const cv::Mat& bgr) const {
    if (bgr.empty() || tracker_) return std::nullopt;
    if (usePosesFile_) {
        auto it = poses_.find(rec.index);
        PoseRow row =
            it != poses_.end() ? it->second : PoseRow{"lost", "no row in the poses file", {}};
        if (row.state != "ok" && row.state != "tracking") row.pose.reset();
        return row;
    }
    if (rec.groundTruth) return PoseRow{"ground_truth", "", rec.groundTruth};
    return PoseRow{"lost", "no ground-truth pose in frames.csv", std::nullopt};
}

}  // namespace mirage::app
