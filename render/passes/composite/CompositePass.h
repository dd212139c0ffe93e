#pragma once
// The compositor: differential rendering of L_rv / L_r into the camera image, with the lens
// distortion applied through the remap table (docs/realtime-renderer.md).
#include "render/RenderPass.h"

namespace mirage::render {

class GBufferPass;

class CompositePass final : public RenderPass {
public:
    explicit CompositePass(const GBufferPass& gbuffer);
    const char* name() const override { return "composite"; }
    std::vector<Resource> reads() const override { return {Resource::CameraImage}; }
    std::vector<Resource> writes() const override { return {Resource::Composite}; }
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx) override;

    // Output (camera image size, top row first): linear RGBA32F (a = coverage) and sRGB8.
    const gl::Texture& linear() const { return linear_; }
    const gl::Texture& srgb() const { return srgb_; }

private:
    const GBufferPass& gbuffer_;
    gl::Program program_;
    gl::Texture linear_, srgb_, remap_;
    gl::Framebuffer fbo_;
};

}  // namespace mirage::render
