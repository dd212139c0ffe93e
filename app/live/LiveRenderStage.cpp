#include "app/live/LiveRenderStage.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <spdlog/spdlog.h>

#include "core/Error.h"
#include "render/passes/direct/DirectLightPass.h"
#include "render/passes/gbuffer/GBufferPass.h"

namespace mirage::app {

const BufferView kBufferViews[] = {{"composite", std::nullopt},
                                   {"L_rv (real + virtual)", render::kLRv},
                                   {"L_r (real only)", render::kLR},
                                   {"direct L_rv", render::kDirectRv},
                                   {"direct L_r", render::kDirectR},
                                   {"G-buffer albedo", render::kGBufferAlbedo},
                                   {"G-buffer normal", render::kGBufferNormal}};
const int kBufferViewCount = int(sizeof kBufferViews / sizeof kBufferViews[0]);

cv::Mat toneMapForView(const cv::Mat& linearRgb) {
    cv::Mat c;
    cv::min(cv::max(linearRgb, 0.0), 1.0, c);
    cv::Mat out(c.size(), CV_8UC3);
    for (int y = 0; y < c.rows; ++y)
        for (int x = 0; x < c.cols; ++x) {
            const cv::Vec3f v = c.at<cv::Vec3f>(y, x);
            cv::Vec3b& o = out.at<cv::Vec3b>(y, x);
            for (int k = 0; k < 3; ++k) {
                const float l = v[2 - k];  // RGB -> BGR
                const float e =
                    l <= 0.0031308f ? 12.92f * l : 1.055f * std::pow(l, 1 / 2.4f) - 0.055f;
                o[k] = uint8_t(std::lround(std::clamp(e, 0.0f, 1.0f) * 255));
            }
        }
    return out;
}

LiveRenderStage::LiveRenderStage(const Scene& scene, const PlacementPlane& plane,
                                 ScenePlacement placement, const CameraIntrinsics& camera,
                                 LiveRenderSettings settings,
                                 const render::EnvironmentCameraSetup* environment)
    : scene_(scene),
      plane_(plane),
      placement_(placement),
      moving_(scene),
      camera_(camera),
      settings_(std::move(settings)) {
    if (environment) environment_ = *environment;
    if (settings_.budgetMs > 0) {
        render::GovernorOptions g;
        g.budgetMs = settings_.budgetMs;
        governor_ = std::make_unique<render::FrameBudgetGovernor>(
            render::SpeedErrorTable::readBenchCsv(!settings_.budgetTable.empty()
                                                      ? settings_.budgetTable
                                                      : std::string(MIRAGE_DEFAULT_DATA_DIR) +
                                                            "/governor/tabletop_llvmpipe.csv"),
            g);
        spdlog::info("live: frame-time budget {:.1f} ms over {} quality settings; {}",
                     settings_.budgetMs, governor_->ladder().size(), governor_->summary());
    }
    rebuild();
}

void LiveRenderStage::rebuild() {
    const QualityPreset& q = kQualityPresets[settings_.preset];
    render::RendererOptions ropt = settings_.effects;
    // The governor switches the half-resolution trace and lighting on while the renderer runs:
    // their programs are built now, not in the frame that first uses them.
    ropt.specular.prepareGovernedVariants = governor_ != nullptr;
    ropt.vpl.count = settings_.vpls;
    ropt.indirect.scale = q.indirectScale;
    ropt.impostor.resolution = q.impostorResolution;
    ropt.composite.exposure = settings_.exposure;
    ropt.environment.lights = settings_.environmentLights;
    // The HUD's direct-light views need the direct light apart in frames with VPLs (two more
    // canvas targets); a headless run shows no view and does not pay for them.
    ropt.direct.keepDirectLight = settings_.keepDirectLight;
    Scene placed = scene_;
    applyPlacement(placed, placement_, plane_);
    compositor_.reset();
    renderer_ = std::make_unique<render::Renderer>(placed, camera_, ropt);
    compositor_ = std::make_unique<FrameCompositor>(*renderer_);
    if (environment_) {
        renderer_->setEnvironmentCamera(*environment_);
        if (!envFrame_.empty()) renderer_->updateEnvironment(envFrame_, envSeconds_);
    }
    ++builds_;
}

CompositedFrame LiveRenderStage::composite(const cv::Mat& bgr, PoseRow pose, bool renderVirtual,
                                           double seconds) {
    if (!governor_) return compositor_->composite(bgr, std::move(pose), renderVirtual, seconds);
    // The frame's quality is the governor's; its time, render + composite + readback (the stage
    // the budget holds), is what the governor learns from.
    render::RendererOptions quality = renderer_->options();
    render::applyQualitySetting(governor_->setting(), quality);
    renderer_->setQuality(quality);
    const auto t0 = std::chrono::steady_clock::now();
    CompositedFrame out = compositor_->composite(bgr, std::move(pose), renderVirtual, seconds);
    if (out.report && governor_->observe(std::chrono::duration<double, std::milli>(
                                             std::chrono::steady_clock::now() - t0)
                                             .count()))
        spdlog::info("live: {}", governor_->summary());
    return out;
}

std::string LiveRenderStage::updateEnvironment(const cv::Mat& bgr, double seconds) {
    try {
        renderer_->updateEnvironment(bgr, seconds);
    } catch (const Error& e) {
        return e.what();
    }
    envFrame_ = bgr;
    envSeconds_ = seconds;
    return "";
}

bool LiveRenderStage::move(const ScenePlacement& placement) {
    placement_ = placement;
    // In every frame of a drag: only the node matrices are reset and placed again.
    moving_.nodes = scene_.nodes;
    applyPlacement(moving_, placement_, plane_);
    return renderer_->updateTransforms(moving_);
}

cv::Mat LiveRenderStage::view(int index) const {
    const BufferView& v = kBufferViews[std::clamp(index, 0, kBufferViewCount - 1)];
    if (!v.resource) return {};
    return toneMapForView(renderer_->readBuffer(*v.resource));
}

}  // namespace mirage::app
