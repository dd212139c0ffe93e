#include "render/passes/specular/SpecularLightPass.h"

#include "render/passes/gbuffer/GBufferPass.h"
#include "render/passes/specular/SpecularGBufferPass.h"
#include "render/passes/vpl/VplPass.h"

namespace mirage::render {

SpecularLightPass::SpecularLightPass(const GBufferPass& gbuffer, const SpecularGBufferPass& hits,
                                     const VplPass& vpls, const GpuScene& scene)
    : gbuffer_(gbuffer),
      hits_(hits),
      vpls_(vpls),
      program_(fullscreenProgram("specular light", "passes/specular/specular_light.frag",
                                 scene.lightingDefines())) {
    locUseVpls_ = program_.uniformLocation("useVpls");
    locVplStride_ = program_.uniformLocation("vplStride");
}

PassDecision SpecularLightPass::decide(const FrameContext& ctx) const {
    if (!ctx.has(Resource::ReflectionGBuffer)) return {false, "no specular G-buffers"};
    const bool vpls = ctx.options.specularVpls && ctx.has(Resource::Vpls) &&
                      ctx.has(Resource::ImperfectShadowMaps);
    return {true, std::to_string(ctx.scene.lights().size()) + " light(s)" +
                      (ctx.scene.hasEnvironment() ? " + environment" : "") +
                      (vpls ? " + VPLs" : "") + " at the reflected/refracted hits"};
}

void SpecularLightPass::resize(const FrameContext& ctx) {
    const int w = ctx.canvasWidth(), h = ctx.canvasHeight();
    if (w == width_ && h == height_) return;
    width_ = w;
    height_ = h;
    rv_ = gl::Texture::create2D("L'_rv", w, h, GL_RGBA16F);
    r_ = gl::Texture::create2D("L'_r", w, h, GL_RGBA16F);
    rRefl_ = gl::Texture::create2D("L'_r reflection share", w, h, GL_RGBA16F);
    env_ = gl::Texture::create2D("L_env", w, h, GL_RGBA16F);
    fbo_ = gl::Framebuffer("specular light fbo");
    fbo_.attachColor(0, rv_);
    fbo_.attachColor(1, r_);
    fbo_.attachColor(2, rRefl_);
    fbo_.attachColor(3, env_);
    fbo_.finalize(4);
}

void SpecularLightPass::execute(FrameContext& ctx) {
    fbo_.bind();
    ctx.beginFullscreen(program_, ctx.canvasWidth(), ctx.canvasHeight());
    const SpecularHitBuffer& a = hits_.reflection();
    const SpecularHitBuffer& b = hits_.refraction();
    const gl::Texture* units[10] = {&a.position, &a.normal, &a.albedo, &a.emissive, &a.weight,
                                    &b.position, &b.normal, &b.albedo, &b.emissive, &b.weight};
    for (GLuint i = 0; i < 10; ++i) glBindTextureUnit(i, units[i]->id());
    glBindTextureUnit(10, ctx.has(Resource::ShadowMaps) ? ctx.texture(Resource::ShadowMaps).id()
                                                        : ctx.farShadowTexture().id());
    glBindTextureUnit(11, ctx.has(Resource::ShadowMapsReal)
                              ? ctx.texture(Resource::ShadowMapsReal).id()
                              : ctx.farShadowTexture().id());
    const bool vpls = ctx.options.specularVpls && ctx.has(Resource::Vpls) &&
                      ctx.has(Resource::ImperfectShadowMaps);
    if (vpls) {
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingVpls, vpls_.vplBuffer().id());
        glBindTextureUnit(12, ctx.texture(Resource::ImperfectShadowMaps).id());
        glBindTextureUnit(13, ctx.has(Resource::ImperfectShadowMapsReal)
                                  ? ctx.texture(Resource::ImperfectShadowMapsReal).id()
                                  : ctx.texture(Resource::ImperfectShadowMaps).id());
    } else {
        glBindTextureUnit(12, 0);
        glBindTextureUnit(13, 0);
    }
    glBindTextureUnit(14, gbuffer_.position().id());
    glBindTextureUnit(kUnitEnvironmentMap, ctx.scene.environmentMap().id());
    glUniform1i(locUseVpls_, vpls ? 1 : 0);
    glUniform1i(locVplStride_, ctx.options.specularVplStride);
    ctx.drawFullscreenTriangle();
    ctx.publish(Resource::SpecularRv, &rv_);
    ctx.publish(Resource::SpecularR, &r_);
    ctx.publish(Resource::Lenv, &env_);
}

}  // namespace mirage::render
