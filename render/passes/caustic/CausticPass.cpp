#include "render/passes/caustic/CausticPass.h"

#include <algorithm>
#include <cmath>

#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/passes/caustic/PhotonGBufferPass.h"
#include "render/passes/gbuffer/GBufferPass.h"

namespace mirage::render {

CausticPass::CausticPass()
    : splat_(computeProgram("caustic splat", "passes/caustic/caustic_splat.comp")),
      resolve_(rasterProgram("caustic resolve", "passes/caustic/caustic_tiles.vert",
                             "passes/caustic/caustic_resolve.frag")),
      tileVao_("caustic tiles") {
    glEnableVertexArrayAttrib(tileVao_.id(), 0);
    glVertexArrayAttribFormat(tileVao_.id(), 0, 2, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(tileVao_.id(), 0, 0);
}

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

CausticReprojection CausticPass::cameras(const FrameContext& ctx) const {
    return {ctx.frame.viewProj, ctx.frame.prevViewProj, glm::vec3(ctx.frame.prevCameraPos),
            ctx.canvasWidth(),  ctx.canvasHeight(),     glm::vec3(ctx.frame.cameraPos)};
}

bool CausticPass::intervalAllowsReuse(const FrameContext& ctx) const {
    const int interval = ctx.options.caustic.refreshInterval;
    return interval > 1 && framesSinceSplat_ + 1 < interval && history_.usable(ctx, 1.0f);
}

float CausticPass::newViewShare(const FrameContext& ctx) const {
    // At the camera distances of last frame's caustic (its lit tiles), else of whatever it
    // resolved, else a wide guess.
    const CausticHistoryTiles& h = lastHistory(ctx);
    float near[2] = {INFINITY, INFINITY}, far[2] = {0.0f, 0.0f};
    for (std::size_t i = 0; i < h.lit.size(); ++i) {
        if (!(h.nearM[i] <= h.farM[i])) continue;
        const int k = h.lit[i] != 0u ? 0 : 1;
        near[k] = std::min(near[k], h.nearM[i]);
        far[k] = std::max(far[k], h.farM[i]);
    }
    for (int k = 0; k < 2; ++k)
        if (near[k] <= far[k]) return render::newViewShare(cameras(ctx), near[k], far[k]);
    return render::newViewShare(cameras(ctx), 0.2f, 5.0f);
}

bool CausticPass::reusesHistory(const FrameContext& ctx) const {
    return intervalAllowsReuse(ctx) && (ctx.options.caustic.reuseMaxNewView >= 1.0f ||
                                        newViewShare(ctx) <= ctx.options.caustic.reuseMaxNewView);
}

PassDecision CausticPass::decide(const FrameContext& ctx) const {
    if (ctx.plan.causticLayers == 0) return {false, ctx.plan.causticReason};
    if (reusesHistory(ctx))
        return {true, "last frame's caustic reprojected (photons splatted every " +
                          std::to_string(ctx.options.caustic.refreshInterval) + " frames)"};
    std::string why;
    if (intervalAllowsReuse(ctx))
        why = " (" + std::to_string(int(std::lround(100.0f * newViewShare(ctx)))) +
              " % of the view new since last frame)";
    return {true, "photon quads of " + std::to_string(ctx.plan.causticLayers) +
                      " light(s) splatted (compute, atomics)" + why + ", " +
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
    const int tw = (w + kCausticTileSize - 1) / kCausticTileSize;
    const int th = (h + kCausticTileSize - 1) / kCausticTileSize;
    photonTiles_ = gl::Texture::create2D("caustic photon tiles", tw, th, GL_R32UI);
    photonTiles_.setFilter(GL_NEAREST, GL_NEAREST);
    tileMarks_.assign(std::size_t(tw) * std::size_t(th), 0);
    // Every tile a run of its own at worst: six vertices each.
    tileVertices_ =
        gl::Buffer("caustic tile quads", std::size_t(tw) * std::size_t(th) * 6 * sizeof(glm::vec2));
    glVertexArrayVertexBuffer(tileVao_.id(), 0, tileVertices_.id(), 0, sizeof(glm::vec2));
    for (int i = 0; i < 2; ++i) {
        historyTiles_[i] = gl::Texture::create2D("caustic history tiles", tw, th, GL_R32UI);
        historyNear_[i] = gl::Texture::create2D("caustic history near", tw, th, GL_R32UI);
        historyFar_[i] = gl::Texture::create2D("caustic history far", tw, th, GL_R32UI);
        for (gl::Texture* t : {&historyTiles_[i], &historyNear_[i], &historyFar_[i]})
            t->setFilter(GL_NEAREST, GL_NEAREST);
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
        fbo_[i].finalize(4);
    }
    history_.drop();  // new buffers hold no history
    historyReadFrame_ = -1;
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
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                    GL_TEXTURE_UPDATE_BARRIER_BIT);  // the tiles are read back
}

// invFixedScale 0: the caustic buffer counts for nothing (a reuse frame: its counters are an
// older frame's, in that frame's pixels); `reuse`: the history is taken whole where it passes.
void CausticPass::resolve(FrameContext& ctx, PassResources& res, float invFixedScale, bool reuse) {
    const int write = history_.writeSlot(), read = history_.readSlot();
    const float blend = reuse ? 1.0f : causticBlend(ctx);
    const bool useHistory = history_.usable(ctx, blend);
    const int vertices = chooseTiles(ctx, !reuse, useHistory);
    // Every pixel 0 (the ones not drawn keep it), then the chosen tiles resolved.
    const GLuint zero = 0, none = 0xFFFFFFFFu;
    glClearTexImage(historyTiles_[write].id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glClearTexImage(historyNear_[write].id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &none);
    glClearTexImage(historyFar_[write].id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    fbo_[write].bind();
    ctx.beginFullscreen(resolve_, width_, height_);
    const float clear[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    for (int i = 0; i < 4; ++i) glClearBufferfv(GL_COLOR, i, clear);
    glBindImageTexture(kImageCausticHistoryTiles, historyTiles_[write].id(), 0, GL_FALSE, 0,
                       GL_WRITE_ONLY, GL_R32UI);
    glBindImageTexture(kImageCausticHistoryNear, historyNear_[write].id(), 0, GL_FALSE, 0,
                       GL_READ_WRITE, GL_R32UI);
    glBindImageTexture(kImageCausticHistoryFar, historyFar_[write].id(), 0, GL_FALSE, 0,
                       GL_READ_WRITE, GL_R32UI);
    glBindTextureUnit(kUnitResolveAccum, accum_.id());
    glBindTextureUnit(kUnitResolvePosition, res.texture(kGBufferPosition).id());
    glBindTextureUnit(kUnitResolveAlbedo, res.texture(kGBufferAlbedo).id());
    glBindTextureUnit(kUnitResolveEmissive, res.texture(kGBufferEmissive).id());
    glBindTextureUnit(kUnitResolveHistoryRv, historyRv_[read].id());
    glBindTextureUnit(kUnitResolveHistoryR, historyR_[read].id());
    glUniform1f(resolve_.uniformLocation("invFixedScale"), invFixedScale);
    glUniform1f(resolve_.uniformLocation("historyWeight"), useHistory ? blend : 0.0f);
    if (vertices > 0) {
        tileVao_.bind();
        glDrawArrays(GL_TRIANGLES, 0, vertices);
    }
    // The next frame reads the history tiles back.
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                    GL_TEXTURE_UPDATE_BARRIER_BIT);  // the tiles are read back
    history_.written(ctx);
    res.publish(kCausticHistoryRv, historyRv_[write]);
    res.publish(kCausticHistoryR, historyR_[write]);
    res.publish(kCausticRv, rv_);
    res.publish(kCausticR, r_);
}

const CausticHistoryTiles& CausticPass::lastHistory(const FrameContext& ctx) const {
    if (historyReadFrame_ == ctx.frameIndex) return lastHistory_;
    historyReadFrame_ = ctx.frameIndex;
    const int tw = (width_ + kCausticTileSize - 1) / kCausticTileSize;
    const int th = (height_ + kCausticTileSize - 1) / kCausticTileSize;
    const std::size_t tiles = std::size_t(tw) * std::size_t(th);
    const GLsizei bytes = GLsizei(tiles * sizeof(std::uint32_t));
    const int read = history_.readSlot();
    CausticHistoryTiles& h = lastHistory_;
    h.tilesX = tw;
    h.tilesY = th;
    h.lit.resize(tiles);
    h.nearM.resize(tiles);
    h.farM.resize(tiles);
    // Last frame's resolve has finished: the read waits for nothing.
    glGetTextureImage(historyTiles_[read].id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, bytes,
                      h.lit.data());
    // r32ui images holding the bits of positive floats (an empty tile: near all ones, a NaN, and
    // far 0: near > far fails as markHistoryTiles expects).
    glGetTextureImage(historyNear_[read].id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, bytes,
                      h.nearM.data());
    glGetTextureImage(historyFar_[read].id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, bytes,
                      h.farM.data());
    return h;
}

int CausticPass::chooseTiles(const FrameContext& ctx, bool photons, bool history) {
    const int tw = (width_ + kCausticTileSize - 1) / kCausticTileSize;
    const int th = (height_ + kCausticTileSize - 1) / kCausticTileSize;
    const std::size_t tiles = std::size_t(tw) * std::size_t(th);
    const GLsizei bytes = GLsizei(tiles * sizeof(std::uint32_t));
    if (ctx.options.caustic.resolveEverywhere) {
        std::fill(tileMarks_.begin(), tileMarks_.end(), std::uint8_t(1));
    } else {
        std::fill(tileMarks_.begin(), tileMarks_.end(), std::uint8_t(0));
        // The reads wait for the splat (this frame) and last frame's resolve, both done by now.
        if (photons) {
            photonTileFlags_.resize(tiles);
            glGetTextureImage(photonTiles_.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, bytes,
                              photonTileFlags_.data());
            for (std::size_t i = 0; i < tiles; ++i)
                if (photonTileFlags_[i] != 0u) tileMarks_[i] = 1;
        }
        if (history && !ctx.options.caustic.tilesIgnoreHistory)
            markHistoryTiles(lastHistory(ctx), cameras(ctx), tileMarks_);
    }
    const std::vector<glm::vec2> quads = tileQuads(tileMarks_, tw, th, width_, height_);
    if (!quads.empty()) tileVertices_.upload(quads.data(), quads.size() * sizeof(glm::vec2));
    return int(quads.size());
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeCausticPass(const PassInit&) {
    return std::make_unique<CausticPass>();
}

}  // namespace mirage::render
