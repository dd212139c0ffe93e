#pragma once
// Direct + environment + emitted light for every G-buffer pixel, into DirectRv / DirectR.
#include "render/RenderPass.h"

namespace mirage::render {

class GBufferPass;
class ShadowPass;

class DirectLightPass final : public RenderPass {
public:
    DirectLightPass(const GBufferPass& gbuffer, const GpuScene& scene);
    const char* name() const override { return "direct"; }
    std::vector<Resource> reads() const override { return {Resource::GBuffer}; }
    std::vector<Resource> writes() const override {
        return {Resource::DirectRv, Resource::DirectR};
    }
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx) override;

private:
    const GBufferPass& gbuffer_;
    gl::Program program_;
    gl::Texture rv_, r_;
    gl::Framebuffer fbo_;
};

}  // namespace mirage::render
