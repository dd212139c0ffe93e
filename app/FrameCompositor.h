#pragma once
// The render and composite stages of every loop that composites footage (mirage replay, mirage
// live): the virtual objects rendered from the frame's decided pose (app/PoseStage.h),
// composited into the frame, read back. One implementation, so that a live session and the
// replay of its recording make the same images from the same frames and poses.
#include <limits>
#include <map>
#include <string>

#include <opencv2/core.hpp>

#include "core/session/PosesCsv.h"
#include "render/Renderer.h"

namespace mirage::app {

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
    // The gain from rendered radiance to camera units the frame was composited with (R, G, B)
    // and where it came from (render::exposureSourceName; empty when nothing was rendered).
    glm::dvec3 exposureGain{0.0};
    std::string exposureSource;
};

class FrameCompositor {
public:
    explicit FrameCompositor(render::Renderer& renderer);

    // One frame: `bgr` 8-bit BGR sRGB (empty = lost) with its decided pose. With a pose (and
    // `renderVirtual`) the renderer renders and composites; without one, or with
    // `renderVirtual` false, the footage passes through (the pose is still reported) and the
    // temporal history is reset on the next rendered frame.
    // `time`: the frame's time in seconds on the footage's clock (the motion blur's frame
    // interval; NaN = unknown, no motion blur).
    CompositedFrame composite(const cv::Mat& bgr, PoseRow pose, bool renderVirtual = true,
                              double time = std::numeric_limits<double>::quiet_NaN());

    // Blits the last composite into the current context's default framebuffer (w x h pixels,
    // flipped to the window's bottom-up rows).
    void blitToWindow(int width, int height) const;

private:
    render::Renderer& renderer_;
    bool lastLost_ = true;
};

}  // namespace mirage::app
