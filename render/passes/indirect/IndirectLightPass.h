#pragma once
// Interleaved VPL gather into IndirectRv / IndirectR (unfiltered; see GiFilterPass).
#include "render/RenderPass.h"

namespace mirage::render {

class GBufferPass;
class VplPass;

class IndirectLightPass final : public RenderPass {
public:
    IndirectLightPass(const GBufferPass& gbuffer, const VplPass& vpls);
    const char* name() const override { return "indirect"; }
    std::vector<Resource> reads() const override {
        return {Resource::GBuffer, Resource::Vpls, Resource::ImperfectShadowMaps,
                Resource::ImperfectShadowMapsReal};
    }
    std::vector<Resource> writes() const override {
        return {Resource::IndirectRv, Resource::IndirectR};
    }
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx) override;

private:
    const GBufferPass& gbuffer_;
    const VplPass& vpls_;
    gl::Program program_;
    gl::Texture rv_, r_;
    gl::Framebuffer fbo_;
};

}  // namespace mirage::render
