#pragma once
// Places VPLs from the reflective shadow maps (compute). Runs only when the plan needs VPLs.
#include "render/RenderPass.h"

namespace mirage::render {

class ShadowPass;

class VplPass final : public RenderPass {
public:
    explicit VplPass(const ShadowPass& shadow);
    const char* name() const override { return "vpl"; }
    std::vector<Resource> reads() const override { return {Resource::ReflectiveShadowMaps}; }
    std::vector<Resource> writes() const override { return {Resource::Vpls}; }
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx) override;
    bool cameraIndependent() const override { return true; }
    void publishCached(FrameContext& ctx) override;
    const gl::Buffer& vplBuffer() const { return vpls_; }

private:
    const ShadowPass& shadow_;
    gl::Program program_;
    gl::Buffer vpls_;
    int allocated_ = 0;
};

}  // namespace mirage::render
