#pragma once
// L'_rv, L'_r and L_env (Knecht 2013 Eqs. 3-5, Sec. 4.1.3): the reflected and refracted hits of
// GBuf_refl / GBuf_refr lit by every light (shadow maps), the environment (SH) and the VPLs
// (imperfect shadow maps), Fresnel-weighted and routed real / virtual; rays that hit nothing
// modelled look up the environment map into L_env (specular_light.frag).
#include "render/RenderPass.h"

namespace mirage::render {

class GBufferPass;
class SpecularGBufferPass;
class VplPass;

class SpecularLightPass final : public RenderPass {
public:
    SpecularLightPass(const GBufferPass& gbuffer, const SpecularGBufferPass& hits,
                      const VplPass& vpls, const GpuScene& scene);
    const char* name() const override { return "speclight"; }
    std::vector<Resource> reads() const override {
        return {Resource::ReflectionGBuffer, Resource::RefractionGBuffer};
    }
    std::vector<Resource> writes() const override {
        return {Resource::SpecularRv, Resource::SpecularR, Resource::Lenv};
    }
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx) override;

    const gl::Texture& rv() const { return rv_; }              // L'_rv, linear
    const gl::Texture& r() const { return r_; }                // L'_r, linear
    const gl::Texture& rReflection() const { return rRefl_; }  // reflection's share of L'_r
    const gl::Texture& env() const { return env_; }            // L_env, linear

private:
    const GBufferPass& gbuffer_;
    const SpecularGBufferPass& hits_;
    const VplPass& vpls_;
    gl::Program program_;
    gl::Texture rv_, r_, rRefl_, env_;
    gl::Framebuffer fbo_;
    GLint locUseVpls_ = -1, locVplStride_ = -1;
    int width_ = 0, height_ = 0;
};

}  // namespace mirage::render
