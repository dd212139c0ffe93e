#include "render/passes/specular/SpecularLightPass.h"

#include <array>

#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/passes/caustic/PhotonGridPass.h"
#include "render/passes/environment/EnvironmentPass.h"
#include "render/passes/gbuffer/GBufferPass.h"
#include "render/passes/ism/IsmPass.h"
#include "render/passes/shadow/ShadowPass.h"
#include "render/passes/specular/SpecularGBufferPass.h"
#include "render/passes/vpl/VplPass.h"

namespace mirage::render {

namespace {
// GBuf_refl then GBuf_refr, at kUnitSpecLightReflFirst + 0..4 and kUnitSpecLightRefrFirst + 0..4.
constexpr Resource kHitBuffers[10] = {kReflectionGBuffer,  kReflectionNormal, kReflectionAlbedo,
                                      kReflectionEmissive, kReflectionWeight, kRefractionGBuffer,
                                      kRefractionNormal,   kRefractionAlbedo, kRefractionEmissive,
                                      kRefractionWeight};
static_assert(kUnitSpecLightRefrFirst == kUnitSpecLightReflFirst + 5);
// L'_rv, L'_r, reflection share (each also the next frame's history), L_env, the hits.
constexpr int kAttachments = 5;
}  // namespace

namespace {
const char* const kKindLabel[2] = {"", ", reflection only"};
const char* const kKindDefine[2] = {"", "#define MIRAGE_REFLECTION_ONLY 1\n"};
}  // namespace

SpecularLightPass::Variant SpecularLightPass::makeVariant(const std::string& label,
                                                          const std::string& defines, int kind) {
    Variant v;
    v.program = fullscreenProgram(label + kKindLabel[kind], "passes/specular/specular_light.frag",
                                  defines + kKindDefine[kind]);
    v.useVpls = v.program.uniformLocation("useVpls");
    v.vplStride = v.program.uniformLocation("vplStride");
    v.cellSize = v.program.uniformLocation("photonCellSize");
    v.gatherCap = v.program.uniformLocation("photonGatherCap");
    v.historyWeight = v.program.uniformLocation("historyWeight");
    v.refreshInterval = v.program.uniformLocation("refreshInterval");
    v.refreshPhase = v.program.uniformLocation("refreshPhase");
    return v;
}

namespace {
// The history's share this frame: RendererOptions::temporalBlend where L' is smoothed. The
// half-resolution variant has no history: its hits are shaded per 2x2 block and upsampled, and
// the history test needs each pixel's own hits.
float specularBlend(const FrameContext& ctx) {
    return ctx.options.specular.temporal && !ctx.options.specular.halfResolution
               ? ctx.options.temporalBlend
               : 0.0f;
}
// The frames over which every hit's light is refreshed this frame (SpecularOptions::
// refreshInterval), 1 where the history cannot stand in for it.
int specularRefresh(const FrameContext& ctx, const TemporalHistory& history) {
    const int n = ctx.options.specular.refreshInterval;
    return n > 1 && !ctx.options.specular.halfResolution && history.usable(ctx, 1.0f) ? n : 1;
}
}  // namespace

SpecularLightPass::SpecularLightPass(const GpuScene& scene, const RendererOptions& options)
    : sceneCanGather_(PhotonGridPass::sceneCanGather(scene, options)) {
    // The kinds of rectangle the scene can have: with glass, and of mirrors alone.
    bool kinds[kKinds] = {false, false};
    for (int i : scene.specularDraws()) kinds[scene.draws()[size_t(i)].transmissive ? 0 : 1] = true;
    for (int kind = 0; kind < kKinds; ++kind) {
        if (!kinds[kind]) continue;
        buildFull(scene, kind);
        if (options.specular.halfResolution || options.specular.prepareGovernedVariants)
            buildHalfResolution(scene, kind);
    }
}

void SpecularLightPass::buildFull(const GpuScene& scene, int kind) {
    if (plain_[kind].program.id() != 0) return;
    plain_[kind] = makeVariant("specular light", scene.lightingDefines(), kind);
    if (sceneCanGather_)
        gather_[kind] =
            makeVariant("specular light (caustic gather)",
                        scene.lightingDefines() + "#define MIRAGE_CAUSTIC_GATHER 1\n", kind);
}

// The half-resolution variants, their upsample and mask (RendererOptions::specular.halfResolution,
// which a frame-time governor may switch on while the renderer runs: built on first use).
void SpecularLightPass::buildHalfResolution(const GpuScene& scene, int kind) {
    if (halfPlain_[kind].program.id() != 0) return;
    const std::string half = scene.lightingDefines() + "#define MIRAGE_SPECULAR_HALF 1\n";
    halfPlain_[kind] = makeVariant("specular light (half resolution)", half, kind);
    if (sceneCanGather_)
        halfGather_[kind] = makeVariant("specular light (half resolution, caustic gather)",
                                        half + "#define MIRAGE_CAUSTIC_GATHER 1\n", kind);
    resolve_[kind] = fullscreenProgram(std::string("specular light upsample") + kKindLabel[kind],
                                       "passes/specular/specular_resolve.frag", kKindDefine[kind]);
    if (halfMaskProgram_.id() == 0)
        halfMaskProgram_ = fullscreenProgram("specular half-resolution mask",
                                             "passes/specular/specular_half_mask.frag");
}

void SpecularLightPass::setup(PassBuilder& b) const {
    for (Resource r : kHitBuffers) b.read(r);
    b.read(kGBufferPosition);
    b.read(kGBufferEmissive);  // the specular slot (half-resolution upsample)
    b.read(kSpecularMask);     // depth attachment: shade specular pixels only
    b.read(kEnvironmentMap);
    b.read(kEnvironmentLight);
    for (Resource r : {kShadowMaps, kShadowMapsReal, kShadowGlass, kShadowGlassReal, kVpls,
                       kImperfectShadowMaps, kImperfectShadowMapsReal, kPhotonGrid, kPhotonRecords})
        b.readOptional(r);
    // This frame's smoothed L', read back by the next frame as temporal history (32-bit: the
    // alpha channels hold the world positions and distances the history test compares).
    b.create(kSpecularRv, {GL_RGBA32F, SizeRule::Canvas, Storage::Persistent});
    b.create(kSpecularR, {GL_RGBA32F, SizeRule::Canvas, Storage::Persistent});
    b.create(kSpecularRReflection, {GL_RGBA32F, SizeRule::Canvas, Storage::Persistent});
    b.create(kLenv, {GL_RGBA16F, SizeRule::Canvas, Storage::PassOwned});
}

PassDecision SpecularLightPass::decide(const FrameContext& ctx) const {
    const bool vpls = ctx.options.specular.vpls && ctx.plan.needVpls;
    return {true, std::to_string(ctx.scene.lights().size()) + " light(s)" +
                      (ctx.scene.hasEnvironment() || ctx.environment.live ? " + environment" : "") +
                      (vpls ? " + VPLs" : "") +
                      (PhotonGridPass::gatherDecision(ctx).run ? " + caustic photons" : "") +
                      " at the reflected/refracted hits" +
                      (ctx.options.specular.halfResolution ? ", half resolution" : "") +
                      refreshNote(ctx) + ", " + history_.note(ctx, specularBlend(ctx))};
}

std::string SpecularLightPass::refreshNote(const FrameContext& ctx) const {
    const int asked = ctx.options.specular.refreshInterval, n = specularRefresh(ctx, history_);
    if (asked <= 1) return "";
    if (n > 1) return ", 1/" + std::to_string(n) + " of the tiles refreshed (the rest reused)";
    return ctx.options.specular.halfResolution ? ""
                                               : ", every pixel refreshed (no history to reuse)";
}

void SpecularLightPass::resize(const FrameContext& ctx) {
    const int w = ctx.canvasWidth(), h = ctx.canvasHeight();
    if (w == width_ && h == height_) return;
    width_ = w;
    height_ = h;
    for (int i = 0; i < 2; ++i) {
        // 32-bit: world positions and distances the history test compares.
        rv_[i] = gl::Texture::create2D("L'_rv", w, h, GL_RGBA32F);
        r_[i] = gl::Texture::create2D("L'_r", w, h, GL_RGBA32F);
        rRefl_[i] = gl::Texture::create2D("L'_r reflection share", w, h, GL_RGBA32F);
        env_[i] = gl::Texture::create2D("L_env", w, h, GL_RGBA16F);
        hits_[i] = gl::Texture::create2D("specular hits", w, h, GL_RGBA32F);
        // Linear: the history is read at reprojected, fractional positions.
        for (gl::Texture* t : {&rv_[i], &r_[i], &rRefl_[i], &hits_[i]})
            t->setFilter(GL_LINEAR, GL_LINEAR);
        fbo_[i] = gl::Framebuffer("specular light fbo");
        fbo_[i].attachColor(0, rv_[i]);
        fbo_[i].attachColor(1, r_[i]);
        fbo_[i].attachColor(2, rRefl_[i]);
        fbo_[i].attachColor(3, env_[i]);
        fbo_[i].attachColor(4, hits_[i]);
        fbo_[i].finalize(kAttachments);
        attachedMask_[i] = 0;  // execute() attaches the specular mask
        drawn_[i].markAll();
    }
    history_.drop();               // new buffers hold no history
    halfWidth_ = halfHeight_ = 0;  // the half-resolution targets follow on first use
    if (ctx.options.specular.halfResolution) allocateHalfResolution(w, h);
}

void SpecularLightPass::allocateHalfResolution(int w, int h) {
    halfWidth_ = (w + 1) / 2;
    halfHeight_ = (h + 1) / 2;
    const int hw = halfWidth_, hh = halfHeight_;
    halfReflRv_ = gl::Texture::create2D("half L_rv at the reflected hit", hw, hh, GL_RGBA16F);
    halfReflR_ = gl::Texture::create2D("half L_r at the reflected hit", hw, hh, GL_RGBA16F);
    halfRefrRv_ = gl::Texture::create2D("half L_rv at the refracted hit", hw, hh, GL_RGBA16F);
    halfRefrR_ = gl::Texture::create2D("half L_r at the refracted hit", hw, hh, GL_RGBA16F);
    for (gl::Texture* t : {&halfReflRv_, &halfReflR_, &halfRefrRv_, &halfRefrR_})
        t->setFilter(GL_NEAREST, GL_NEAREST);
    halfMask_ = gl::Texture::create2D("half specular pixel mask", hw, hh, GL_DEPTH_COMPONENT32F);
    halfMaskFbo_ = gl::Framebuffer("half specular pixel mask fbo");
    halfMaskFbo_.attachDepth(halfMask_);
    halfMaskFbo_.finalize(0);
    halfMaskDrawn_.markAll();
    halfDrawn_.markAll();
    halfFbo_ = gl::Framebuffer("half specular light fbo");
    halfFbo_.attachColor(0, halfReflRv_);
    halfFbo_.attachColor(1, halfReflR_);
    halfFbo_.attachColor(2, halfRefrRv_);
    halfFbo_.attachColor(3, halfRefrR_);
    halfFbo_.attachDepth(halfMask_);
    halfFbo_.finalize(4);
}

void SpecularLightPass::clearAndDraw(FrameContext& ctx, const PassResources& res, int write,
                                     const Variant (&variants)[kKinds]) {
    ctx.clearForRects(ctx.specularRects, drawn_[write], 0, kAttachments);
    drawKinds(ctx, res, variants, {ctx.glassSpecularRects, ctx.mirrorRects}, ctx.canvasWidth(),
              ctx.canvasHeight());
}

// Only specular pixels pass the early depth test against the bound framebuffer's mask (the
// triangle lies at depth 0.5); the rest stay as cleared (0: not a specular pixel).
void SpecularLightPass::drawKinds(FrameContext& ctx, const PassResources& res,
                                  const Variant (&variants)[kKinds],
                                  const std::vector<glm::ivec4> (&rects)[kKinds], int width,
                                  int height) {
    for (int kind = 0; kind < kKinds; ++kind) {
        if (rects[kind].empty()) continue;
        // A kind's rectangles come from the scene's draws of that kind, whose variants the
        // constructor built; built here rather than drawn with no program should that change.
        if (variants[kind].program.id() == 0) {
            buildFull(ctx.scene, kind);
            if (ctx.options.specular.halfResolution) buildHalfResolution(ctx.scene, kind);
        }
        ctx.beginFullscreen(variants[kind].program, width, height);
        setUniforms(ctx, res, variants[kind]);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_GREATER);
        glDepthMask(GL_FALSE);
        ctx.drawFullscreenTriangleIn(rects[kind]);
    }
}

namespace {
// Canvas rectangles in half pixels, rounded outwards.
std::vector<glm::ivec4> halfRectsOf(const std::vector<glm::ivec4>& rects) {
    std::vector<glm::ivec4> out;
    for (const glm::ivec4& s : rects)
        out.push_back(
            {s.x / 2, s.y / 2, (s.x + s.z + 1) / 2 - s.x / 2, (s.y + s.w + 1) / 2 - s.y / 2});
    return mergeOverlappingRects(std::move(out));
}
}  // namespace

void SpecularLightPass::shadeHalfResolution(FrameContext& ctx, PassResources& res, bool gather,
                                            int write) {
    // The specular objects' rectangles in half pixels, rounded outwards; by kind (a half pixel
    // shared by a mirror's and a glass's rectangle goes to the glass).
    const std::vector<glm::ivec4> halfRects = halfRectsOf(ctx.specularRects);
    std::vector<glm::ivec4> kindRects[kKinds] = {halfRectsOf(ctx.glassSpecularRects),
                                                 halfRectsOf(ctx.mirrorRects)};
    separateMirrorRects(kindRects[0], kindRects[1]);
    halfMaskFbo_.bind();
    ctx.beginFullscreen(halfMaskProgram_, halfWidth_, halfHeight_);
    glDepthMask(GL_TRUE);
    ctx.clearForRects(halfRects, halfMaskDrawn_, 0, 0, true);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_ALWAYS);
    ctx.drawFullscreenTriangleIn(halfRects);
    halfFbo_.bind();
    glDepthMask(GL_FALSE);
    ctx.clearForRects(halfRects, halfDrawn_, 0, 4);
    drawKinds(ctx, res, gather ? halfGather_ : halfPlain_, kindRects, halfWidth_, halfHeight_);
    // The upsample, on the canvas's specular pixels. It writes L'_rv, L'_r, the reflection's
    // share and L_env, and 0 hits (no history at half resolution: specularBlend).
    fbo_[write].bind();
    const gl::Texture* half[4] = {&halfReflRv_, &halfReflR_, &halfRefrRv_, &halfRefrR_};
    for (int i = 0; i < 4; ++i)
        glBindTextureUnit(GLuint(kUnitSpecResolveHalfFirst + i), half[i]->id());
    glBindTextureUnit(kUnitSpecResolveSlot, res.texture(kGBufferEmissive).id());
    ctx.clearForRects(ctx.specularRects, drawn_[write], 0, kAttachments);
    const std::vector<glm::ivec4>* canvasRects[kKinds] = {&ctx.glassSpecularRects,
                                                          &ctx.mirrorRects};
    for (int kind = 0; kind < kKinds; ++kind) {
        if (canvasRects[kind]->empty()) continue;
        const gl::Program& resolve = resolve_[kind];
        ctx.beginFullscreen(resolve, ctx.canvasWidth(), ctx.canvasHeight());
        glUniform1i(resolve.uniformLocation("geometryTest"),
                    ctx.options.specular.upsampleGeometry ? 1 : 0);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_GREATER);
        glDepthMask(GL_FALSE);
        ctx.drawFullscreenTriangleIn(*canvasRects[kind]);
    }
}

void SpecularLightPass::setUniforms(const FrameContext& ctx, const PassResources& res,
                                    const Variant& v) const {
    if (v.cellSize >= 0) glUniform1f(v.cellSize, PhotonGridPass::cellSize(ctx.options));
    if (v.gatherCap >= 0) glUniform1ui(v.gatherCap, GLuint(ctx.options.caustic.gatherCap));
    const bool vpls = ctx.options.specular.vpls && res.has(kVpls) && res.has(kImperfectShadowMaps);
    glUniform1i(v.useVpls, vpls ? 1 : 0);
    glUniform1i(v.vplStride, ctx.options.specular.vplStride);
    if (v.historyWeight >= 0) {
        const float blend = specularBlend(ctx);
        glUniform1f(v.historyWeight, history_.usable(ctx, blend) ? blend : 0.0f);
    }
    if (v.refreshInterval >= 0) {
        const int n = specularRefresh(ctx, history_);
        glUniform1i(v.refreshInterval, n);
        glUniform1i(v.refreshPhase, int(ctx.frameIndex % n));
    }
}

void SpecularLightPass::execute(FrameContext& ctx, PassResources& res) {
    const int write = history_.writeSlot(), read = history_.readSlot();
    const gl::Texture& mask = res.texture(kSpecularMask);
    if (mask.id() != attachedMask_[write]) {  // specgbuf reallocates it only on a resize
        fbo_[write].attachDepth(mask);
        fbo_[write].finalize(kAttachments);
        attachedMask_[write] = mask.id();
    }
    // The gather variant only in frames with a photon grid: llvmpipe pays for a branch's buffer
    // reads even when no pixel takes it.
    const bool gather = sceneCanGather_ && res.has(kPhotonGrid) && res.has(kPhotonRecords);
    for (int i = 0; i < 10; ++i)
        glBindTextureUnit(GLuint(kUnitSpecLightReflFirst + i), res.texture(kHitBuffers[i]).id());
    glBindTextureUnit(kUnitSpecLightShadowAll,
                      res.textureOr(kShadowMaps, ctx.farShadowTexture()).id());
    glBindTextureUnit(kUnitSpecLightShadowReal,
                      res.textureOr(kShadowMapsReal, ctx.farShadowTexture()).id());
    glBindTextureUnit(kUnitSpecLightGlassAll,
                      res.textureOr(kShadowGlass, ctx.noGlassTexture()).id());
    glBindTextureUnit(kUnitSpecLightGlassReal,
                      res.textureOr(kShadowGlassReal, ctx.noGlassTexture()).id());
    const bool vpls = ctx.options.specular.vpls && res.has(kVpls) && res.has(kImperfectShadowMaps);
    if (vpls) {
        vplTexels_.attachBuffer(res.buffer(kVpls), GL_RGBA32F);
        glBindTextureUnit(kUnitSpecLightVpls, vplTexels_.id());
        glBindTextureUnit(kUnitSpecLightIsmAll, res.texture(kImperfectShadowMaps).id());
        glBindTextureUnit(
            kUnitSpecLightIsmReal,
            res.textureOr(kImperfectShadowMapsReal, res.texture(kImperfectShadowMaps)).id());
    } else {
        glBindTextureUnit(kUnitSpecLightVpls, 0);
        glBindTextureUnit(kUnitSpecLightIsmAll, 0);
        glBindTextureUnit(kUnitSpecLightIsmReal, 0);
    }
    glBindTextureUnit(kUnitSpecLightPosition, res.texture(kGBufferPosition).id());
    glBindTextureUnit(kUnitEnvironmentMap, res.texture(kEnvironmentMap).id());
    glBindBufferBase(GL_UNIFORM_BUFFER, kBindingEnvironment, res.buffer(kEnvironmentLight).id());
    if (gather) {
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingPhotonGrid,
                         res.buffer(kPhotonGrid).id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingPhotons,
                         res.buffer(kPhotonRecords).id());
    }
    glBindTextureUnit(kUnitSpecLightHistoryRv, rv_[read].id());
    glBindTextureUnit(kUnitSpecLightHistoryR, r_[read].id());
    glBindTextureUnit(kUnitSpecLightHistoryRRefl, rRefl_[read].id());
    glBindTextureUnit(kUnitSpecLightHistoryHits, hits_[read].id());
    if (ctx.options.specular.halfResolution) {
        for (int kind = 0; kind < kKinds; ++kind)
            if (plain_[kind].program.id() != 0) buildHalfResolution(ctx.scene, kind);
        if (halfWidth_ == 0) allocateHalfResolution(width_, height_);
        shadeHalfResolution(ctx, res, gather, write);
    } else {
        fbo_[write].bind();
        // Every attachment cleared: a history texel outside the specular pixels holds distance 0.
        clearAndDraw(ctx, res, write, gather ? gather_ : plain_);
    }
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    glDisable(GL_DEPTH_TEST);
    res.publish(kSpecularRv, rv_[write]);
    res.publish(kSpecularR, r_[write]);
    res.publish(kSpecularRReflection, rRefl_[write]);
    res.publish(kLenv, env_[write]);
    history_.written(ctx);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeSpecularLightPass(const PassInit& init) {
    return std::make_unique<SpecularLightPass>(init.gpuScene, init.options);
}

}  // namespace mirage::render
