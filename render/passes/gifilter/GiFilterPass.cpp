#include "render/passes/gifilter/GiFilterPass.h"

#include <algorithm>
#include <string>

#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/passes/gbuffer/GBufferPass.h"
#include "render/passes/indirect/IndirectLightPass.h"

namespace mirage::render {

GiFilterPass::GiFilterPass(int interleave)
    : filter_(fullscreenProgram(
          "gi filter", "passes/gifilter/filter.frag",
          "#define MIRAGE_INTERLEAVE " + std::to_string(std::max(1, interleave)))) {}

void GiFilterPass::setup(PassBuilder& b) const {
    b.read(kGBufferPosition);
    b.read(kGBufferNormal);
    b.read(kIndirectRv);
    b.read(kIndirectR);
    // This frame's filtered indirect light, read back by the next frame as temporal history.
    b.create(kGiHistoryRv, {GL_RGBA32F, SizeRule::Gather, Storage::Persistent});
    b.create(kGiHistoryR, {GL_RGBA32F, SizeRule::Gather, Storage::Persistent});
    b.create(kGatherLight, {GL_RGBA32UI, SizeRule::Gather, Storage::PassOwned});
}

PassDecision GiFilterPass::decide(const FrameContext& ctx) const {
    return {true, std::string("geometry-aware ") + std::to_string(ctx.options.indirect.interleave) +
                      "x" + std::to_string(ctx.options.indirect.interleave) + ", " +
                      history_.note(ctx, ctx.options.temporalBlend)};
}

void GiFilterPass::resize(const FrameContext& ctx) {
    const int w = ctx.canvasWidth(), h = ctx.canvasHeight(), s = ctx.gatherScale();
    // Runs before every frame: reallocating would also throw the temporal history away.
    const int lowW = (w + s - 1) / s, lowH = (h + s - 1) / s;
    if (lowRv_[0].width() == lowW && lowRv_[0].height() == lowH) return;
    gatherLight_ = gl::Texture::create2D("indirect upsample light", lowW, lowH, GL_RGBA32UI);
    gatherLight_.setFilter(GL_NEAREST, GL_NEAREST);
    for (int i = 0; i < 2; ++i) {
        // 32-bit: alpha holds the camera distance the history test compares (temporal.glsl).
        lowRv_[i] = gl::Texture::create2D("indirect L_rv filtered", lowW, lowH, GL_RGBA32F);
        lowR_[i] = gl::Texture::create2D("indirect L_r filtered", lowW, lowH, GL_RGBA32F);
        // Linear: the history is read at reprojected, fractional positions.
        lowRv_[i].setFilter(GL_LINEAR, GL_LINEAR);
        lowR_[i].setFilter(GL_LINEAR, GL_LINEAR);
        lowFbo_[i] = gl::Framebuffer("gi filter fbo");
        lowFbo_[i].attachColor(0, lowRv_[i]);
        lowFbo_[i].attachColor(1, lowR_[i]);
        lowFbo_[i].attachColor(2, gatherLight_);
        lowFbo_[i].finalize(3);
    }
    history_.drop();  // new buffers hold no history
}

void GiFilterPass::execute(FrameContext& ctx, PassResources& res) {
    const int write = history_.writeSlot(), read = history_.readSlot();
    lowFbo_[write].bind();
    ctx.beginFullscreen(filter_, lowRv_[write].width(), lowRv_[write].height());
    glUniform1i(filter_.uniformLocation("scale"), ctx.gatherScale());
    glUniform1f(filter_.uniformLocation("historyWeight"),
                history_.usable(ctx, ctx.options.temporalBlend) ? ctx.options.temporalBlend : 0.0f);
    glBindTextureUnit(kUnitFilterPosition, res.texture(kGBufferPosition).id());
    glBindTextureUnit(kUnitFilterNormal, res.texture(kGBufferNormal).id());
    glBindTextureUnit(kUnitFilterIndirectRv, res.texture(kIndirectRv).id());
    glBindTextureUnit(kUnitFilterIndirectR, res.texture(kIndirectR).id());
    glBindTextureUnit(kUnitFilterHistoryRv, lowRv_[read].id());
    glBindTextureUnit(kUnitFilterHistoryR, lowR_[read].id());
    ctx.drawFullscreenTriangle();
    history_.written(ctx);
    res.publish(kGiHistoryRv, lowRv_[write]);
    res.publish(kGiHistoryR, lowR_[write]);
    res.publish(kGatherLight, gatherLight_);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeGiFilterPass(const PassInit& init) {
    return std::make_unique<GiFilterPass>(init.options.indirect.interleave);
}

}  // namespace mirage::render
