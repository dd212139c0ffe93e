#include "render/passes/indirect/IndirectLightPass.h"

#include "render/Shaders.h"
#include "render/passes/gbuffer/GBufferPass.h"
#include "render/passes/vpl/VplPass.h"

namespace mirage::render {

IndirectLightPass::IndirectLightPass(const GBufferPass& gbuffer, const VplPass& vpls)
    : gbuffer_(gbuffer),
      vpls_(vpls),
      program_("indirect",
               {{GL_VERTEX_SHADER, "fullscreen.vert", shaders::source("fullscreen.vert")},
                {GL_FRAGMENT_SHADER, "passes/indirect/indirect.frag",
                 shaders::source("passes/indirect/indirect.frag")}}) {}

PassDecision IndirectLightPass::decide(const FrameContext& ctx) const {
    if (!ctx.plan.needVpls) return {false, "no VPLs this frame"};
    const int k = std::max(1, ctx.options.interleave);
    return {true, "interleaved " + std::to_string(k) + "x" + std::to_string(k) + ": " +
                      std::to_string((ctx.options.vplCount + k * k - 1) / (k * k)) +
                      " VPLs per pixel"};
}

void IndirectLightPass::resize(const FrameContext& ctx) {
    rv_ = gl::Texture::create2D("indirect L_rv", ctx.canvasWidth(), ctx.canvasHeight(), GL_RGBA16F);
    r_ = gl::Texture::create2D("indirect L_r", ctx.canvasWidth(), ctx.canvasHeight(), GL_RGBA16F);
    rv_.setFilter(GL_NEAREST, GL_NEAREST);
    r_.setFilter(GL_NEAREST, GL_NEAREST);
    fbo_ = gl::Framebuffer("indirect fbo");
    fbo_.attachColor(0, rv_);
    fbo_.attachColor(1, r_);
    fbo_.finalize(2);
}

void IndirectLightPass::execute(FrameContext& ctx) {
    fbo_.bind();
    glViewport(0, 0, rv_.width(), rv_.height());
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    program_.use();
    glUniform1i(program_.uniformLocation("scale"), ctx.options.indirectScale);
    ctx.bindFrameBlocks();
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingVpls, vpls_.vplBuffer().id());
    glBindTextureUnit(0, gbuffer_.position().id());
    glBindTextureUnit(1, gbuffer_.normal().id());
    glBindTextureUnit(2, gbuffer_.albedo().id());
    glBindTextureUnit(3, ctx.texture(Resource::ImperfectShadowMaps).id());
    glBindTextureUnit(4, ctx.texture(Resource::ImperfectShadowMapsReal).id());
    ctx.emptyVao.bind();
    glDrawArrays(GL_TRIANGLES, 0, 3);
    ctx.publish(Resource::IndirectRv, &rv_);
    ctx.publish(Resource::IndirectR, &r_);
}

}  // namespace mirage::render
