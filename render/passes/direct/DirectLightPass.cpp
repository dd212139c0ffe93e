#include "render/passes/direct/DirectLightPass.h"

#include "render/passes/gbuffer/GBufferPass.h"

namespace mirage::render {

DirectLightPass::DirectLightPass(const GBufferPass& gbuffer, const GpuScene& scene)
    : gbuffer_(gbuffer),
      program_(fullscreenProgram("direct", "passes/direct/direct.frag", scene.lightingDefines())) {}

PassDecision DirectLightPass::decide(const FrameContext& ctx) const {
    if (!ctx.has(Resource::GBuffer)) return {false, "no G-buffer"};
    return {true, std::to_string(ctx.scene.lights().size()) + " light(s)" +
                      (ctx.scene.hasEnvironment() ? " + environment" : "")};
}

void DirectLightPass::resize(const FrameContext& ctx) {
    if (rv_.width() == ctx.canvasWidth() && rv_.height() == ctx.canvasHeight()) return;
    rv_ = gl::Texture::create2D("direct L_rv", ctx.canvasWidth(), ctx.canvasHeight(), GL_RGBA16F);
    r_ = gl::Texture::create2D("direct L_r", ctx.canvasWidth(), ctx.canvasHeight(), GL_RGBA16F);
    fbo_ = gl::Framebuffer("direct fbo");
    fbo_.attachColor(0, rv_);
    fbo_.attachColor(1, r_);
    fbo_.finalize(2);
}

void DirectLightPass::execute(FrameContext& ctx) {
    fbo_.bind();
    ctx.beginFullscreen(program_, ctx.canvasWidth(), ctx.canvasHeight());
    glBindTextureUnit(0, gbuffer_.position().id());
    glBindTextureUnit(1, gbuffer_.normal().id());
    glBindTextureUnit(2, gbuffer_.albedo().id());
    glBindTextureUnit(3, gbuffer_.emissive().id());
    glBindTextureUnit(4, ctx.has(Resource::ShadowMaps) ? ctx.texture(Resource::ShadowMaps).id()
                                                       : ctx.farShadowTexture().id());
    glBindTextureUnit(5, ctx.has(Resource::ShadowMapsReal)
                             ? ctx.texture(Resource::ShadowMapsReal).id()
                             : ctx.farShadowTexture().id());
    ctx.drawFullscreenTriangle();
    ctx.publish(Resource::DirectRv, &rv_);
    ctx.publish(Resource::DirectR, &r_);
}

}  // namespace mirage::render
