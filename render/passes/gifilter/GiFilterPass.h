#pragma once
// Geometry-aware + temporal filter of the VPL light, summed with direct light into LRv / LR:
// de-interleave at gather resolution (deinterleave.frag), then joint bilateral upsampling,
// temporal smoothing and the sum (gifilter.frag). Keeps two history buffers (ping-pong).
#include "render/RenderPass.h"

namespace mirage::render {

class GBufferPass;

class GiFilterPass final : public RenderPass {
public:
    explicit GiFilterPass(const GBufferPass& gbuffer);
    const char* name() const override { return "gifilter"; }
    std::vector<Resource> reads() const override {
        return {Resource::GBuffer, Resource::IndirectRv, Resource::IndirectR, Resource::DirectRv,
                Resource::DirectR};
    }
    std::vector<Resource> writes() const override { return {Resource::LRv, Resource::LR}; }
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx) override;

private:
    const GBufferPass& gbuffer_;
    gl::Program deinterleave_;  // K x K geometry-aware filter at gather resolution
    gl::Program program_;       // upsampling + temporal + sum with direct light
    gl::Texture lowRv_, lowR_;
    gl::Framebuffer lowFbo_;
    gl::Texture rv_, r_;
    gl::Texture historyRv_[2], historyR_[2];
    gl::Framebuffer fbo_[2];
    int current_ = 0;
};

}  // namespace mirage::render
