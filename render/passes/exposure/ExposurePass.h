#pragma once
// The main camera's exposure and white balance, measured every frame (docs/camera-matching.md):
// the real proxies are rendered with the session's light anyway (L_r), so the footage over L_r,
// per channel, over well-exposed real surfaces that no virtual object hides, is the gain from
// rendered radiance to camera units. exposure_samples.frag summarises the canvas in blocks
// (mean footage and mean L_r of each usable block) at a reduced resolution; the blocks are read
// back, their ratios go to the one ratio estimator (render/RadiometricRatio.h) and the result to
// the temporal filter (render/ExposureTracker.h); the gain lands in the frame block's `exposure`
// before the passes that use it (specular video terms, fuzzy, rough, composite) run.
//
// Runs after the direct light and caustic passes (L_r complete) and before the specular passes.
// Without RendererOptions::exposureMatch.enabled it does not run and `exposure` stays
// RendererOptions::composite.exposure.
#include <vector>

#include "render/ExposureTracker.h"
#include "render/RenderPass.h"

namespace mirage::render {

// The sample blocks of this frame (RGBA32F, sampleColumns wide): rgb = mean linear footage,
// a = 1 for a usable block. Read by nothing on the GPU: the composite declares it so that the
// graph keeps this pass and orders it first (the frame block's exposure is its real output).
inline constexpr Resource kExposureSamples{"ExposureSamples"};

class ExposurePass final : public RenderPass {
public:
    ExposurePass();
    const char* name() const override { return "exposure"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

    // The block grid for a canvas: columns x rows of blocks of `block` canvas pixels per side,
    // read with taps x taps taps `stride` pixels apart.
    struct Grid {
        int columns = 0, rows = 0, block = 1, taps = 1, stride = 1;
    };
    static Grid grid(int canvasWidth, int canvasHeight, int sampleColumns);
    // Each block centre's squared normalised radius in the camera image (vignetteRadius2), -1
    // where no camera pixel sees it; `canvasToCamera` is CameraProjection::canvasToCameraTable()
    // of a canvas canvasWidth pixels wide. The exposure and grain passes share the blocks.
    static std::vector<float> blockRadii2(const Grid& grid, int canvasWidth, int canvasHeight,
                                          const std::vector<glm::vec2>& canvasToCamera,
                                          const CameraIntrinsics& camera);

private:
    gl::Program program_;
    Grid grid_;
    gl::Texture footage_, rendered_, canvasToCamera_;
    gl::Framebuffer fbo_;
    int canvasW_ = 0, canvasH_ = 0;
    std::vector<float> footageRead_, renderedRead_;  // readback storage (allocated in resize)
    // Each block centre's squared normalised radius in the camera image (vignetteRadius2; -1
    // where no camera pixel sees it): the blocks are divided by the vignetting in force.
    std::vector<float> blockR2_;
    ExposureTracker tracker_;
    bool trackerConfigured_ = false;
};

}  // namespace mirage::render
