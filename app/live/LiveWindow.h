#pragma once
// The present stage of a live session with a window (GLFW + Dear ImGui): the view (the composite
// or one of the renderer's buffers) scaled to the space left of the HUD, the HUD beside it
// (state, timings, quality, effects, placement, recording) and the keys. It only displays and
// reports what the user asked for (HudRequests); the session decides what follows.
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include "app/FrameCompositor.h"
#include "app/WindowSupport.h"
#include "core/camera/CameraModel.h"
#include "core/gl/Context.h"
#include "core/gl/Objects.h"
#include "core/scene/ScenePlacement.h"
#include "render/FrameContext.h"

namespace mirage::app {

inline constexpr int kHudWidth = 330;  // pixels, right of the view

// What the user switches in the window and the loop follows.
struct LiveControls {
    bool paused = false, hideVirtual = false;
    int view = 0;  // kBufferViews index
    int preset = 0;
    render::RendererOptions effects;  // the effect switches
};

// What the HUD shows (read only).
struct HudStatus {
    std::string lostReason;  // non-empty: the camera is lost
    double fps = 0, latencyMs = 0;
    // How far ahead of its capture the last frame's pose was predicted (to its display time),
    // ms; NaN: not predicted (shown as tracked). Tracking on its own thread (pipelined) or not.
    double predictMs = 0;
    bool pipelined = false;
    long long dropped = 0, driverDropped = 0;
    const CompositedFrame* last = nullptr;  // the last processed frame (pose, pass report)
    std::string exposureText;
    std::vector<std::string> exposureWarnings;
    std::string environmentText;  // empty: no environment camera
    // The frame-time governor's choice and why (FrameBudgetGovernor::summary); empty: no budget.
    std::string budgetText;
    std::string viewProblem;
    std::string recordingText;  // empty: not recording
    std::string scanText;       // --scan's countdown while it scans; empty otherwise
    ScenePlacement placement;
    bool placementPending = false;
};

// What the user asked for in this window frame.
struct HudRequests {
    bool close = false, screenshot = false, toggleRecord = false;
    bool rebuild = false;                     // the quality preset or an effect changed
    std::optional<ScenePlacement> placement;  // moved by keys or a drag
};

class LiveWindow {
public:
    // `ctx` is a window context; `camera` the main camera (the view's size, and picking on the
    // board's `plane` for drags).
    LiveWindow(gl::Context& ctx, const CameraIntrinsics& camera, const PlacementPlane& plane);

    // The image the view shows from now on (8-bit BGR, camera size).
    void show(const cv::Mat& bgr);
    // One window frame: events, the view, the HUD, the keys. Leaves the frame drawn in the back
    // buffer (saveWindowPng can take it) until swap().
    HudRequests draw(const HudStatus& status, LiveControls& controls);
    void swap() { ctx_.swapBuffers(); }
    void savePng(const std::string& path) const;
    bool dragging() const { return dragStart_.has_value(); }

private:
    std::optional<ScenePlacement> placementInput(const HudStatus& status, float scale);
    HudRequests drawHud(const HudStatus& status, LiveControls& controls, int fbw, int fbh);

    gl::Context& ctx_;
    CameraIntrinsics camera_;
    PlacementPlane plane_;
    ImGuiScope imgui_;
    gl::Texture shown_;  // what the view shows, RGBA8
    cv::Mat shownRgba_;
    std::optional<glm::dvec3> dragStart_;  // where a left-drag started on the board plane
    ScenePlacement dragFrom_;
};

}  // namespace mirage::app
