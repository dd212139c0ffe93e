#pragma once
// Interleaved VPL gather into IndirectRv / IndirectR (unfiltered; see GiFilterPass).
#include "render/RenderPass.h"

namespace mirage::render {

class IndirectLightPass final : public RenderPass {
public:
    IndirectLightPass();
    const char* name() const override { return "indirect"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    gl::Program program_;
    gl::Texture rv_, r_;
    gl::Framebuffer fbo_;
    gl::Texture vplTexels_ = gl::Texture::createBufferView("VPL texels (indirect)");
};

}  // namespace mirage::render
