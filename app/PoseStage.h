#pragma once
// The tracking stage of every loop that composites footage (mirage replay, mirage live): each
// frame's pose decision (tracked, or given by the caller) and the rule for uncertain poses. One
// implementation, so that a live session and the replay of its recording decide alike.
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "core/session/PosesCsv.h"
#include "tracking/Tracker.h"

namespace mirage::app {

// How long an `uncertain` frame may be composited with the last ok pose (seconds).
inline constexpr double kHoldUncertainS = 0.25;

class PoseStage {
public:
    // `tracker` may be null when every frame's pose is given by the caller.
    explicit PoseStage(tracking::Tracker* tracker);

    // One frame: `bgr` 8-bit BGR sRGB (empty = lost, `problem` says why), `t` its time in
    // seconds. `given`: the pose decided elsewhere (a poses file, the ground truth); nullopt:
    // track the frame. The pose returned is T_world_camera (OpenCV axes), or none: the footage
    // passes through. An uncertain pose is never used as it is; for up to kHoldUncertainS
    // after the last ok pose that pose is held (a short wobble of the tracking does not blink
    // the virtual objects away), later the frame counts as lost.
    PoseRow decide(const cv::Mat& bgr, double t, const std::string& problem,
                   std::optional<PoseRow> given);

    // What made the last frame's tracked pose ("board", "board+features", "features only");
    // empty when the pose was given or the frame lost before tracking.
    const std::string& lastMode() const { return lastMode_; }

    // Forgets the held pose (a renderer built anew starts its history again).
    void restart();

private:
    tracking::Tracker* tracker_;
    std::optional<Pose> lastGood_;  // the last ok (or given) pose, and its time (seconds)
    double lastGoodT_ = 0;
    std::string lastMode_;
};

}  // namespace mirage::app
