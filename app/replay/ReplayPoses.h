#pragma once
// Where `mirage replay` takes each frame's camera pose from, in this order: --poses POSES.csv
// (the `mirage track` format); --ground-truth (the session's frames.csv poses); otherwise
// tracking (app/PoseStage.h with a tracking::Tracker on the session's board and calibration)
// when the session has a board file, else the ground truth as a fallback.
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/session/PosesCsv.h"
#include "core/session/Session.h"
#include "tracking/Tracker.h"

namespace mirage::app {

class ReplayPoses {
public:
    // `posesFile` empty: no poses file. `boardOnly`: track the tags alone, no natural features.
    // Logs which source it chose.
    ReplayPoses(const Session& session, const CameraIntrinsics& camera,
                const std::string& posesFile, bool groundTruth, bool boardOnly = false);

    // The pose decided outside tracking for session row `row` whose image is `bgr`: nullopt
    // when the frame is tracked (or is lost: an empty image). A row missing from the poses
    // file is lost, and a pose whose state is neither ok nor tracking is not used.
    std::optional<PoseRow> given(const FrameRecord& row, const cv::Mat& bgr) const;
    tracking::Tracker* tracker() const { return tracker_.get(); }

private:
    std::map<int, PoseRow> poses_;
    bool usePosesFile_ = false;
    std::unique_ptr<tracking::Tracker> tracker_;
};

}  // namespace mirage::app
