#pragma once
// The per-frame work of every command that composites footage (mirage replay, mirage live): pose
// (tracked, or given by the caller), the rule for uncertain poses, render, composite, readback.
// One implementation, so that a live session and the replay of its recording make the same
// decisions on the same frames and therefore the same images.
#include <map>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "core/session/PosesCsv.h"
#include "render/Renderer.h"
#include "tracking/Tracker.h"

namespace mirage::app {

// How long an `uncertain` frame may be composited with the last ok pose (seconds).
inline constexpr double kHoldUncertainS = 0.25;

struct CompositedFrame {
    // State and reason of the frame, and the pose composited (T_world_camera, OpenCV axes);
    // no pose: the footage passed through unchanged.
    PoseRow pose;
    // What made the tracked pose ("board", "board+features", "features only"; empty: the pose
    // was given, not tracked).
    std::string trackingMode;
    double trackingMs = 0;                 // wall time of the pose decision (tracking), ms
    std::map<std::string, double> passMs;  // GL timer-query time per pass that ran, ms
    double gpuMs = 0, readbackMs = 0;
    // The composite, 8-bit BGR sRGB-encoded (the footage itself when there is no pose); empty
    // for a lost frame (no image to composite into).
    cv::Mat image;
    const render::FrameReport* report = nullptr;  // the renderer's report, when it rendered
};

class FrameCompositor {
public:
    // `tracker` may be null when every frame's pose is given by the caller.
    FrameCompositor(render::Renderer& renderer, tracking::Tracker* tracker);

    // One frame: `bgr` 8-bit BGR sRGB (empty = lost, `problem` says why), `t` its time in
    // seconds. `given`: the pose decided elsewhere (a poses file, the ground truth); nullopt:
    // track the frame. An uncertain pose is never composited; for up to kHoldUncertainS after
    // the last ok pose that pose is held (a short wobble of the tracking does not blink the
    // virtual objects away), later the footage passes through as for a loss, and the temporal
    // history is reset on the next frame with a pose. `renderVirtual` false: the footage passes
    // through even with a pose (the pose is still reported).
    CompositedFrame process(const cv::Mat& bgr, double t, const std::string& problem,
                            std::optional<PoseRow> given, bool renderVirtual = true);

    // Blits the last composite into the current context's default framebuffer (w x h pixels,
    // flipped to the window's bottom-up rows).
    void blitToWindow(int width, int height) const;

private:
    render::Renderer& renderer_;
    tracking::Tracker* tracker_;
    bool lastLost_ = true;
    std::optional<Pose> lastGood_;  // the last composited ok (or given) pose, and its time
    double lastGoodT_ = 0;
};

}  // namespace mirage::app
