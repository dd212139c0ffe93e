#pragma once
// Places VPLs from the reflective shadow maps (compute). Runs only when the plan needs VPLs.
#include "render/RenderPass.h"

namespace mirage::render {

// SSBO of GpuVpl (vplCount entries).
inline constexpr Resource kVpls{"Vpls"};

// Frame `frame`'s offset of the VPLs' Hammersley set in the RSM image square (each axis in
// [0, 1); frame 0: none), VplOptions::temporalRotation.
glm::vec2 vplSampleOffset(int frame);

class VplPass final : public RenderPass {
public:
    VplPass();
    const char* name() const override { return "vpl"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;
    bool cameraIndependent() const override { return true; }
    bool staticThisFrame(const FrameContext& ctx) const override;

private:
    gl::Program program_;
    gl::Buffer vpls_;
    int allocated_ = 0;
};

}  // namespace mirage::render
