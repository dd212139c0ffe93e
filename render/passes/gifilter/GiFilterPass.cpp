#include "render/passes/gifilter/GiFilterPass.h"

#include "render/Shaders.h"
#include "render/passes/gbuffer/GBufferPass.h"

namespace mirage::render {

GiFilterPass::GiFilterPass(const GBufferPass& gbuffer)
    : gbuffer_(gbuffer),
      deinterleave_("gi deinterleave",
                    {{GL_VERTEX_SHADER, "fullscreen.vert", shaders::source("fullscreen.vert")},
                     {GL_FRAGMENT_SHADER, "passes/gifilter/deinterleave.frag",
                      shaders::source("passes/gifilter/deinterleave.frag")}}),
      program_("gifilter",
               {{GL_VERTEX_SHADER, "fullscreen.vert", shaders::source("fullscreen.vert")},
                {GL_FRAGMENT_SHADER, "passes/gifilter/gifilter.frag",
                 shaders::source("passes/gifilter/gifilter.frag")}}) {}

PassDecision GiFilterPass::decide(const FrameContext& ctx) const {
    if (!ctx.has(Resource::IndirectRv)) return {false, "no indirect light to filter"};
    return {true,
            std::string("geometry-aware ") + std::to_string(ctx.options.interleave) + "x" +
                std::to_string(ctx.options.interleave) +
                (ctx.historyValid && ctx.options.temporalBlend > 0 ? ", temporal history used"
                                                                   : ", temporal history reset")};
}

void GiFilterPass::resize(const FrameContext& ctx) {
    const int w = ctx.canvasWidth(), h = ctx.canvasHeight(), s = ctx.options.indirectScale;
    lowRv_ = gl::Texture::create2D("indirect L_rv filtered", (w + s - 1) / s, (h + s - 1) / s,
                                   GL_RGBA16F);
    lowR_ = gl::Texture::create2D("indirect L_r filtered", (w + s - 1) / s, (h + s - 1) / s,
                                  GL_RGBA16F);
    lowRv_.setFilter(GL_NEAREST, GL_NEAREST);
    lowR_.setFilter(GL_NEAREST, GL_NEAREST);
    lowFbo_ = gl::Framebuffer("gi deinterleave fbo");
    lowFbo_.attachColor(0, lowRv_);
    lowFbo_.attachColor(1, lowR_);
    lowFbo_.finalize(2);
    rv_ = gl::Texture::create2D("L_rv", w, h, GL_RGBA16F);
    r_ = gl::Texture::create2D("L_r", w, h, GL_RGBA16F);
    for (int i = 0; i < 2; ++i) {
        historyRv_[i] = gl::Texture::create2D("history L_rv indirect", w, h, GL_RGBA32F);
        historyR_[i] = gl::Texture::create2D("history L_r indirect", w, h, GL_RGBA32F);
        fbo_[i] = gl::Framebuffer("gifilter fbo");
        fbo_[i].attachColor(0, rv_);
        fbo_[i].attachColor(1, r_);
        fbo_[i].attachColor(2, historyRv_[i]);
        fbo_[i].attachColor(3, historyR_[i]);
        fbo_[i].finalize(4);
    }
}

void GiFilterPass::execute(FrameContext& ctx) {
    const int write = current_, read = 1 - current_;
    lowFbo_.bind();
    glViewport(0, 0, lowRv_.width(), lowRv_.height());
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    deinterleave_.use();
    glUniform1i(deinterleave_.uniformLocation("scale"), ctx.options.indirectScale);
    ctx.bindFrameBlocks();
    glBindTextureUnit(0, gbuffer_.position().id());
    glBindTextureUnit(1, gbuffer_.normal().id());
    glBindTextureUnit(2, ctx.texture(Resource::IndirectRv).id());
    glBindTextureUnit(3, ctx.texture(Resource::IndirectR).id());
    ctx.emptyVao.bind();
    glDrawArrays(GL_TRIANGLES, 0, 3);

    fbo_[write].bind();
    glViewport(0, 0, ctx.canvasWidth(), ctx.canvasHeight());
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    program_.use();
    glUniform1i(program_.uniformLocation("scale"), ctx.options.indirectScale);
    ctx.bindFrameBlocks();
    glBindTextureUnit(0, gbuffer_.position().id());
    glBindTextureUnit(1, gbuffer_.normal().id());
    glBindTextureUnit(2, lowRv_.id());
    glBindTextureUnit(3, lowR_.id());
    glBindTextureUnit(4, ctx.texture(Resource::DirectRv).id());
    glBindTextureUnit(5, ctx.texture(Resource::DirectR).id());
    glBindTextureUnit(6, historyRv_[read].id());
    glBindTextureUnit(7, historyR_[read].id());
    ctx.emptyVao.bind();
    glDrawArrays(GL_TRIANGLES, 0, 3);
    current_ = read;
    ctx.publish(Resource::LRv, &rv_);
    ctx.publish(Resource::LR, &r_);
}

}  // namespace mirage::render
