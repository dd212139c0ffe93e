#include "render/passes/caustic/CausticPass.h"

#include <algorithm>

#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/passes/caustic/PhotonGBufferPass.h"
#include "render/passes/gbuffer/GBufferPass.h"

namespace mirage::render {

CausticPass::CausticPass()
    : splat_(computeProgram("caustic splat", "passes/caustic/caustic_splat.comp")),
      classify_(fullscreenProgram("caustic pixel mask", "passes/caustic/caustic_classify.frag")),
      resolve_(fullscreenProgram("caustic resolve", "passes/caustic/caustic_resolve.frag")) {}

namespace {
// The history's share this frame: RendererOptions::temporalBlend where caustics are smoothed.
float causticBlend(const FrameContext& ctx) {
    return ctx.options.caustic.temporal ? ctx.options.temporalBlend : 0.0f;
}
}  // namespace

void CausticPass::setup(PassBuilder& b) const {
    for (Resource r : {kPhotonHitRefl, kPhotonPowerRefl, kPhotonHitRefr, kPhotonPowerRefr,
                       kGBufferPosition, kGBufferNormal, kGBufferAlbedo, kGBufferEmissive})
        b.read(r);
    b.create(kCausticRv, {GL_RGBA16F, SizeRule::Canvas, Storage::PassOwned});
    b.create(kCausticR, {GL_RGBA16F, SizeRule::Canvas, Storage::PassOwned});
    // This frame's smoothed irradiance, read back by the next frame as temporal history.
    b.create(kCausticHistoryRv, {GL_RGBA32F, SizeRule::Canvas, Storage::Persistent});
    b.create(kCausticHistoryR, {GL_RGBA32F, SizeRule::Canvas, Storage::Persistent});
}

bool CausticPass::reusesHistory(const FrameContext& ctx) const {
    const int interval = ctx.options.caustic.refreshInterval;
    return interval > 1 && framesSinceSplat_ + 1 < interval && history_.usable(ctx, 1.0f);
}

PassDecision CausticPass::decide(const FrameContext& ctx) const {
    if (ctx.plan.causticLayers == 0) return {false, ctx.plan.causticReason};
    if (reusesHistory(ctx))
        return {true, "last frame's caustic reprojected (photons splatted every " +
                          std::to_string(ctx.options.caustic.refreshInterval) + " frames)"};
    return {true, "photon quads of " + std::to_string(ctx.plan.causticLayers) +
                      " light(s) splatted (compute, atomics), " +
                      history_.note(ctx, causticBlend(ctx))};
}

void CausticPass::resize(const FrameContext& ctx) {
    const int w = ctx.canvasWidth(), h = ctx.canvasHeight();
    if (w == width_ && h == height_) return;
    width_ = w;
    height_ = h;
    accum_ = gl::Texture::create2DArray("caustic buffer (fixed point)", w, h, 6, GL_R32UI);
    accum_.setFilter(GL_NEAREST, GL_NEAREST);
    rv_ = gl::Texture::create2D("caustic L_rv", w, h, GL_RGBA16F);
    r_ = gl::Texture::create2D("caustic L_r", w, h, GL_RGBA16F);
    const int tw = (w + 7) / 8, th = (h + 7) / 8;
    photonTiles_ = gl::Texture::create2D("caustic photon tiles", tw, th, GL_R32UI);
    photonTiles_.setFilter(GL_NEAREST, GL_NEAREST);
    resolveMask_ = gl::Texture::create2D("caustic pixel mask", w, h, GL_DEPTH_COMPONENT32F);
    maskFbo_ = gl::Framebuffer("caustic pixel mask fbo");
    maskFbo_.attachDepth(resolveMask_);
    maskFbo_.finalize(0);
    for (int i = 0; i < 2; ++i) {
        historyTiles_[i] = gl::Texture::create2D("caustic history tiles", tw, th, GL_R32UI);
        historyTiles_[i].setFilter(GL_NEAREST, GL_NEAREST);
        // 32-bit: alpha holds the camera distance the history test compares (temporal.glsl).
        historyRv_[i] =
            gl::Texture::create2D("caustic irradiance L_rv (history)", w, h, GL_RGBA32F);
        historyR_[i] = gl::Texture::create2D("caustic irradiance L_r (history)", w, h, GL_RGBA32F);
        // Linear: the history is read at reprojected, fractional positions.
        historyRv_[i].setFilter(GL_LINEAR, GL_LINEAR);
        historyR_[i].setFilter(GL_LINEAR, GL_LINEAR);
        fbo_[i] = gl::Framebuffer("caustic fbo");
        fbo_[i].attachColor(0, rv_);
        fbo_[i].attachColor(1, r_);
        fbo_[i].attachColor(2, historyRv_[i]);
        fbo_[i].attachColor(3, historyR_[i]);
        fbo_[i].attachDepth(resolveMask_);
        fbo_[i].finalize(4);
    }
    history_.drop();  // new buffers hold no history
}

void CausticPass::execute(FrameContext& ctx, PassResources& res) {
    // Fixed point: 2^24 units = 64 x the brightest caustic light's irradiance at its objects, so
    // a counter wraps only past ~16,000 times that (a focus far beyond what a pixel can hold)
    // while ~4e-6 of it still counts.
    const float fixedScale = 16777216.0f / (64.0f * std::max(ctx.plan.causticIrradiance, 1e-6f));
    const bool reuse = reusesHistory(ctx);
    framesSinceSplat_ = reuse ? framesSinceSplat_ + 1 : 0;
    if (!reuse) splat(ctx, res, fixedScale);
    resolve(ctx, res, reuse ? 0.0f : 1.0f / fixedScale, reuse);
}

void CausticPass::splat(FrameContext& ctx, PassResources& res, float fixedScale) {
    const GLuint zero = 0;
    glClearTexImage(accum_.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glClearTexImage(photonTiles_.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glBindImageTexture(kImageCausticPhotonTiles, photonTiles_.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY,
                       GL_R32UI);
    splat_.use();
    ctx.bindFrameBlocks();
    glBindTextureUnit(kUnitSplatReflHit, res.texture(kPhotonHitRefl).id());
    glBindTextureUnit(kUnitSplatReflPower, res.texture(kPhotonPowerRefl).id());
    glBindTextureUnit(kUnitSplatRefrHit, res.texture(kPhotonHitRefr).id());
    glBindTextureUnit(kUnitSplatRefrPower, res.texture(kPhotonPowerRefr).id());
    glBindTextureUnit(kUnitSplatPosition, res.texture(kGBufferPosition).id());
    glBindTextureUnit(kUnitSplatNormal, res.texture(kGBufferNormal).id());
    glBindTextureUnit(kUnitSplatEmissive, res.texture(kGBufferEmissive).id());
    glBindImageTexture(kImageCausticAccum, accum_.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
    const int s = ctx.options.caustic.mapSize;
    glUniform1i(splat_.uniformLocation("mapSize"), s);
    glUniform1f(splat_.uniformLocation("quadScale"), ctx.options.caustic.quadScale);
    glUniform1f(splat_.uniformLocation("fixedScale"), fixedScale);
    glDispatchCompute(GLuint((s + 7) / 8), GLuint((s + 7) / 8), GLuint(2 * ctx.plan.causticLayers));
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
}

// invFixedScale 0: the caustic buffer counts for nothing (a reuse frame: its counters are an
// older frame's, in that frame's pixels); `reuse`: the history is taken whole where it passes.
void CausticPass::resolve(FrameContext& ctx, PassResources& res, float invFixedScale, bool reuse) {
    const int write = history_.writeSlot(), read = history_.readSlot();
    const float blend = reuse ? 1.0f : causticBlend(ctx);
    const bool useHistory = history_.usable(ctx, blend);
    // The pixels to shade: depth 0 in resolveMask_.
    maskFbo_.bind();
    ctx.beginFullscreen(classify_, width_, height_);
    glBindTextureUnit(kUnitClassifyPosition, res.texture(kGBufferPosition).id());
    glBindTextureUnit(kUnitClassifyEmissive, res.texture(kGBufferEmissive).id());
    glBindTextureUnit(kUnitClassifyPhotonTiles, photonTiles_.id());
    glBindTextureUnit(kUnitClassifyHistoryTiles, historyTiles_[read].id());
    glUniform1i(classify_.uniformLocation("usePhotons"), reuse ? 0 : 1);
    glUniform1i(classify_.uniformLocation("useHistory"),
                useHistory && !ctx.options.caustic.maskIgnoresHistory ? 1 : 0);
    glUniform1i(classify_.uniformLocation("everywhere"),
                ctx.options.caustic.resolveEverywhere ? 1 : 0);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_ALWAYS);
    glDepthMask(GL_TRUE);
    ctx.drawFullscreenTriangle();
    // Every pixel 0 (the ones not shaded keep it), then the marked pixels resolved.
    const GLuint zero = 0;
    glClearTexImage(historyTiles_[write].id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    fbo_[write].bind();
    ctx.beginFullscreen(resolve_, width_, height_);
    const float clear[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    for (int i = 0; i < 4; ++i) glClearBufferfv(GL_COLOR, i, clear);
    glBindImageTexture(kImageCausticHistoryTiles, historyTiles_[write].id(), 0, GL_FALSE, 0,
                       GL_WRITE_ONLY, GL_R32UI);
    glBindTextureUnit(kUnitResolveAccum, accum_.id());
    glBindTextureUnit(kUnitResolvePosition, res.texture(kGBufferPosition).id());
    glBindTextureUnit(kUnitResolveAlbedo, res.texture(kGBufferAlbedo).id());
    glBindTextureUnit(kUnitResolveEmissive, res.texture(kGBufferEmissive).id());
    glBindTextureUnit(kUnitResolveHistoryRv, historyRv_[read].id());
    glBindTextureUnit(kUnitResolveHistoryR, historyR_[read].id());
    glUniform1f(resolve_.uniformLocation("invFixedScale"), invFixedScale);
    glUniform1f(resolve_.uniformLocation("historyWeight"), useHistory ? blend : 0.0f);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);  // the triangle lies at depth 0.5: where the mask is 0
    glDepthMask(GL_FALSE);
    ctx.drawFullscreenTriangle();
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    glDisable(GL_DEPTH_TEST);
    // The next frame's classification reads the history tiles.
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    history_.written(ctx);
    res.publish(kCausticHistoryRv, historyRv_[write]);
    res.publish(kCausticHistoryR, historyR_[write]);
    res.publish(kCausticRv, rv_);
    res.publish(kCausticR, r_);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeCausticPass(const PassInit&) {
    return std::make_unique<CausticPass>();
}

}  // namespace mirage::render
