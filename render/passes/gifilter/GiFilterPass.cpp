#include "render/passes/gifilter/GiFilterPass.h"

#include <algorithm>
#include <string>

#include "render/passes/gbuffer/GBufferPass.h"

namespace mirage::render {

GiFilterPass::GiFilterPass(const GBufferPass& gbuffer, int interleave)
    : gbuffer_(gbuffer),
      filter_(fullscreenProgram(
          "gi filter", "passes/gifilter/filter.frag",
          "#define MIRAGE_INTERLEAVE " + std::to_string(std::max(1, interleave)))),
      upsample_(fullscreenProgram("gi upsample", "passes/gifilter/upsample.frag")) {}

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
    // Runs before every frame: reallocating would also throw the temporal history away.
    if (rv_.width() == w && rv_.height() == h && lowRv_[0].width() == (w + s - 1) / s &&
        lowRv_[0].height() == (h + s - 1) / s)
        return;
    for (int i = 0; i < 2; ++i) {
        // 32-bit: alpha holds the camera distance the history test compares to within 0.5 %.
        lowRv_[i] = gl::Texture::create2D("indirect L_rv filtered", (w + s - 1) / s,
                                          (h + s - 1) / s, GL_RGBA32F);
        lowR_[i] = gl::Texture::create2D("indirect L_r filtered", (w + s - 1) / s, (h + s - 1) / s,
                                         GL_RGBA32F);
        // Linear: the history is read at reprojected, fractional positions.
        lowRv_[i].setFilter(GL_LINEAR, GL_LINEAR);
        lowR_[i].setFilter(GL_LINEAR, GL_LINEAR);
        lowFbo_[i] = gl::Framebuffer("gi filter fbo");
        lowFbo_[i].attachColor(0, lowRv_[i]);
        lowFbo_[i].attachColor(1, lowR_[i]);
        lowFbo_[i].finalize(2);
    }
    rv_ = gl::Texture::create2D("L_rv", w, h, GL_RGBA16F);
    r_ = gl::Texture::create2D("L_r", w, h, GL_RGBA16F);
    fbo_ = gl::Framebuffer("gi upsample fbo");
    fbo_.attachColor(0, rv_);
    fbo_.attachColor(1, r_);
    fbo_.finalize(2);
}

void GiFilterPass::execute(FrameContext& ctx) {
    const int write = current_, read = 1 - current_;
    lowFbo_[write].bind();
    ctx.beginFullscreen(filter_, lowRv_[write].width(), lowRv_[write].height());
    glUniform1i(filter_.uniformLocation("scale"), ctx.options.indirectScale);
    glBindTextureUnit(0, gbuffer_.position().id());
    glBindTextureUnit(1, gbuffer_.normal().id());
    glBindTextureUnit(2, ctx.texture(Resource::IndirectRv).id());
    glBindTextureUnit(3, ctx.texture(Resource::IndirectR).id());
    glBindTextureUnit(4, lowRv_[read].id());
    glBindTextureUnit(5, lowR_[read].id());
    ctx.drawFullscreenTriangle();

    fbo_.bind();
    ctx.beginFullscreen(upsample_, ctx.canvasWidth(), ctx.canvasHeight());
    glUniform1i(upsample_.uniformLocation("scale"), ctx.options.indirectScale);
    glBindTextureUnit(0, gbuffer_.position().id());
    glBindTextureUnit(1, gbuffer_.normal().id());
    glBindTextureUnit(2, lowRv_[write].id());
    glBindTextureUnit(3, lowR_[write].id());
    glBindTextureUnit(4, ctx.texture(Resource::DirectRv).id());
    glBindTextureUnit(5, ctx.texture(Resource::DirectR).id());
    ctx.drawFullscreenTriangle();
    current_ = read;
    ctx.publish(Resource::LRv, &rv_);
    ctx.publish(Resource::LR, &r_);
}

}  // namespace mirage::render
