#pragma once
// Anti-aliasing of the renderer's contribution to the composite (antialias.frag,
// docs/camera-matching.md "Anti-aliasing"): a new version of Composite / CompositeSrgb in which
// the virtual objects' silhouettes and their shadows' edges are blended as a box-filtered pixel
// would see them, while every pixel the renderer left alone keeps the footage bit for bit. It
// works on the camera image after the differential composite, so the composite's depth
// validation and back-projection see the same buffers as without it, and lens distortion has
// already been applied.
#include "render/RenderPass.h"
#include "render/passes/composite/CompositeVersion.h"

namespace mirage::render {

class AntialiasPass final : public RenderPass {
public:
    AntialiasPass();
    const char* name() const override { return "aa"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    gl::Program program_;
    gl::Sampler bilinear_;  // the filter reads both images between pixel centres
    CompositeVersion output_{"antialiased composite"};
    GLint locEdgeThreshold_ = -1, locEdgeThresholdMin_ = -1, locSubpixel_ = -1;
    GLint locChangeEpsilon_ = -1, locSearchSteps_ = -1;
};

}  // namespace mirage::render
