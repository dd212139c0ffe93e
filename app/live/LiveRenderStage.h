#pragma once
// The render and composite stages of a live session: the renderer for the scene as placed, the
// per-frame compositing shared with replay (app/FrameCompositor.h), the environment camera's
// frames as they arrive, and the renderer built anew when the quality, the effects or a
// placement that cannot move in place change. Needs a current GL 4.5 context.
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "app/FrameCompositor.h"
#include "core/scene/Scene.h"
#include "core/scene/ScenePlacement.h"
#include "render/Renderer.h"
#include "render/governor/FrameBudgetGovernor.h"

namespace mirage::app {

// Quality presets of the HUD: VPLs, gather scale (0 = automatic by the canvas width, 1 = full
// resolution), impostor resolution.
struct QualityPreset {
    const char* name;
    int vpls, indirectScale, impostorResolution;
};
inline constexpr QualityPreset kQualityPresets[] = {
    {"low", 64, 0, 128}, {"medium", 256, 0, 256}, {"high", 1024, 1, 512}};
inline constexpr int kQualityPresetCount = 3;
inline constexpr int kDefaultQualityPreset = 1;  // medium: the renderer's defaults

// What the HUD can show instead of the composite (canvas-size linear buffers, tone-mapped by
// clamping to [0, 1] and sRGB encoding).
struct BufferView {
    const char* name;
    std::optional<render::Resource> resource;  // nullopt: the composite
};
extern const BufferView kBufferViews[];
extern const int kBufferViewCount;

// A linear RGB float buffer (top row first) shown as sRGB 8-bit BGR.
cv::Mat toneMapForView(const cv::Mat& linearRgb);

// How the renderer is built: the effects as switched, the quality preset and what the session
// fixes (exposure, lights found in the environment, direct light kept apart for the HUD).
struct LiveRenderSettings {
    render::RendererOptions effects;  // the effect switches (--off, then the HUD)
    int preset = kDefaultQualityPreset;
    int vpls = 256;  // --vpls, until a preset is chosen
    float exposure = 1.0f;
    int environmentLights = 0;
    bool keepDirectLight = false;
    // The frame-time budget (ms) the governor holds by choosing each frame's quality
    // (render/governor/; docs/live.md, "Frame-time budget"); 0: off, every frame at full quality.
    double budgetMs = 0;
    // The `mirage bench` bench.csv it chooses from; empty: data/governor/tabletop_llvmpipe.csv.
    std::string budgetTable;
};

class LiveRenderStage {
public:
    // `scene` as loaded (placed here), `plane` the board's plane the placement moves on.
    // `environment`: the environment camera's setup, or null.
    LiveRenderStage(const Scene& scene, const PlacementPlane& plane, ScenePlacement placement,
                    const CameraIntrinsics& camera, LiveRenderSettings settings,
                    const render::EnvironmentCameraSetup* environment);

    // Renders and composites one frame with its decided pose (FrameCompositor::composite).
    // `seconds`: the frame's capture time (the motion blur's frame interval).
    CompositedFrame composite(const cv::Mat& bgr, PoseRow pose, bool renderVirtual,
                              double seconds = std::numeric_limits<double>::quiet_NaN());

    // A new environment frame lights the scene from the next render on. Returns the problem
    // when the renderer refuses it (wrong size), "" otherwise.
    std::string updateEnvironment(const cv::Mat& bgr, double seconds);
    bool hasEnvironmentFrame() const { return !envFrame_.empty(); }
    double environmentSeconds() const { return envSeconds_; }

    // Moves the virtual objects to `placement` in place; false when that cannot be done in
    // place (a translucent object): the next rebuild() applies it.
    bool move(const ScenePlacement& placement);
    const ScenePlacement& placement() const { return placement_; }

    // Quality and effects: both take effect with the next rebuild().
    LiveRenderSettings& settings() { return settings_; }
    // A new renderer for the scene as placed, with the settings; the temporal history starts
    // again and the environment camera's last frame is given to it.
    void rebuild();
    // Builds done so far (the first included).
    int builds() const { return builds_; }

    // The HUD's buffer view `index` of the last rendered frame (tone-mapped, 8-bit BGR).
    cv::Mat view(int index) const;
    std::vector<std::string> passNames() const { return renderer_->passNames(); }
    render::Renderer& renderer() { return *renderer_; }
    // The governor when a budget is set (null otherwise): what it chose and why.
    const render::FrameBudgetGovernor* governor() const { return governor_.get(); }

private:
    const Scene& scene_;
    PlacementPlane plane_;
    ScenePlacement placement_;
    Scene moving_;  // the scene as moved in place: copied once, then only its nodes reset
    CameraIntrinsics camera_;
    LiveRenderSettings settings_;
    std::optional<render::EnvironmentCameraSetup> environment_;
    cv::Mat envFrame_;  // the last environment frame the renderer took, and its time
    double envSeconds_ = 0;
    std::unique_ptr<render::Renderer> renderer_;
    std::unique_ptr<FrameCompositor> compositor_;
    std::unique_ptr<render::FrameBudgetGovernor> governor_;
    int builds_ = 0;
};

}  // namespace mirage::app
