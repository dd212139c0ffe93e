#pragma once
// Direct + environment + emitted light for every G-buffer pixel, into DirectRv / DirectR.
#include "render/RenderPass.h"

namespace mirage::render {

class DirectLightPass final : public RenderPass {
public:
    explicit DirectLightPass(const GpuScene& scene);
    const char* name() const override { return "direct"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    gl::Program program_, programNoGlass_;  // with / without MIRAGE_GLASS_SHADOWS
    gl::Texture rv_, r_;
    gl::Framebuffer fbo_;
    GLuint attachedMask_ = 0;  // the SpecularMask texture attached as fbo_'s depth
};

}  // namespace mirage::render
