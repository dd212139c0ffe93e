#pragma once
// L'_rv, L'_r and L_env (Knecht 2013 Eqs. 3-5, Sec. 4.1.3): the reflected and refracted hits of
// GBuf_refl / GBuf_refr lit by every light (shadow maps), the environment (SH) and the VPLs
// (imperfect shadow maps), Fresnel-weighted and routed real / virtual; rays that hit nothing
// modelled look up the environment map into L_env (specular_light.frag).
#include "render/RenderPass.h"

namespace mirage::render {

class SpecularLightPass final : public RenderPass {
public:
    explicit SpecularLightPass(const GpuScene& scene);
    const char* name() const override { return "speclight"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    gl::Program program_;
    gl::Texture rv_, r_, rRefl_, env_;
    gl::Framebuffer fbo_;
    GLuint attachedMask_ = 0;  // the SpecularMask texture attached as fbo_'s depth
    GLint locUseVpls_ = -1, locVplStride_ = -1;
    int width_ = 0, height_ = 0;
};

}  // namespace mirage::render
