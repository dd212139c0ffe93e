#pragma once
// Interleaved VPL gather into IndirectRv / IndirectR (unfiltered; see GiFilterPass).
#include "render/RenderPass.h"

namespace mirage::render {

// Interleaved VPL gather, deinterleaved and unfiltered (gather size, transient).
inline constexpr Resource kIndirectRv{"IndirectRv"};
inline constexpr Resource kIndirectR{"IndirectR"};

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
    TargetFramebuffer fbo_{"indirect fbo"};
    gl::Texture vplTexels_ = gl::Texture::createBufferView("VPL texels (indirect)");
};

}  // namespace mirage::render
