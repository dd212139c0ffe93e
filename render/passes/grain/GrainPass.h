#pragma once
// The camera's noise and vignetting on what the renderer adds (docs/camera-matching.md). Runs
// after the composite (and every pass that modifies it: the noise goes on last, as the sensor
// adds it last):
//  1. grain_samples.frag summarises the canvas in sample blocks (as the exposure pass's) where
//     the footage shows a smooth, unhidden, unclipped real surface: the mean footage and L_r, the
//     variance of the footage around L_r scaled to the block (the noise) and its neighbouring
//     pixels' correlation. The blocks are read back; the CPU estimators (CameraGrain.h) make the
//     frame's noise-level function and vignetting fit, smoothed over frames.
//  2. grain_apply.frag writes the new composite: virtual pixels times V(r) (the real surfaces'
//     pixels carry the camera's vignetting already through the footage and alpha = CI / L_r);
//     then on every pixel the noise the footage would have at the new value that the pixel does
//     not have yet: all of it on virtual pixels, the difference on real pixels the differential
//     changed (a pixel L = k CI carries the footage's noise times k), none on unchanged ones.
//     The noise is a hash of the pixel, the channel and the frame: reproducible.
#include <vector>

#include "render/RenderPass.h"
#include "render/passes/composite/CompositeVersion.h"
#include "render/passes/exposure/ExposurePass.h"

namespace mirage::render {

class GrainPass final : public RenderPass {
public:
    GrainPass();
    const char* name() const override { return "grain"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    void sampleBlocks(FrameContext& ctx, PassResources& res);
    void estimate(FrameContext& ctx);
    void apply(FrameContext& ctx, PassResources& res);

    gl::Program samplesProgram_, applyProgram_;
    ExposurePass::Grid grid_;
    gl::Texture footage_, rendered_, noise_, position_, canvasToCamera_;
    gl::Framebuffer samplesFbo_;
    CompositeVersion output_{"grain"};
    int canvasW_ = 0, canvasH_ = 0;
    std::vector<float> footageRead_, renderedRead_, noiseRead_, positionRead_;
    std::vector<float> blockR2_;  // each block centre's squared normalised radius (camera image)
};

}  // namespace mirage::render
