#pragma once
// The caustic buffer and its light (Knecht 2013 Sec. 4.2.1, 5.2; docs/caustics.md): the
// photons of the photon G-buffers splatted as quads in camera space by a compute shader (integer
// atomics into a fixed-point irradiance buffer, depth-rejected against the G-buffer), then
// resolved into the caustic radiance the receivers reflect, routed into L_rv and L_r by Eqs.
// 12-14. The composite adds CausticRv / CausticR to the GI solutions.
#include "render/RenderPass.h"

namespace mirage::render {

class CausticPass final : public RenderPass {
public:
    CausticPass();
    const char* name() const override { return "caustic"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    gl::Program splat_, resolve_;
    gl::Texture accum_, rv_, r_;
    gl::Framebuffer fbo_;
    int width_ = 0, height_ = 0;
};

}  // namespace mirage::render
