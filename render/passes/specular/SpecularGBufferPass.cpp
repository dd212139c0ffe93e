#include "render/passes/specular/SpecularGBufferPass.h"

#include <array>

#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/passes/backface/BackFacePass.h"
#include "render/passes/gbuffer/GBufferPass.h"
#include "render/passes/impostor/ImpostorPass.h"

namespace mirage::render {
namespace {

void allocate(SpecularHitBuffer& b, const std::string& what, int w, int h) {
    b.position = gl::Texture::create2D(what + " position", w, h, GL_RGBA32F);
    b.normal = gl::Texture::create2D(what + " normal", w, h, GL_RGBA16F);
    b.albedo = gl::Texture::create2D(what + " albedo", w, h, GL_RGBA16F);
    b.emissive = gl::Texture::create2D(what + " emissive", w, h, GL_RGBA16F);
    b.weight = gl::Texture::create2D(what + " weight", w, h, GL_RGBA16F);
    for (gl::Texture* t : {&b.position, &b.normal, &b.albedo, &b.emissive, &b.weight})
        t->setFilter(GL_NEAREST, GL_NEAREST);
    b.fbo = gl::Framebuffer(what + " fbo");
    b.fbo.attachColor(0, b.position);
    b.fbo.attachColor(1, b.normal);
    b.fbo.attachColor(2, b.albedo);
    b.fbo.attachColor(3, b.emissive);
    b.fbo.attachColor(4, b.weight);
    b.fbo.finalize(5);  // execute() attaches the specular mask
    b.drawn.markAll();
}

void publish(PassResources& res, const SpecularHitBuffer& b, Resource position, Resource normal,
             Resource albedo, Resource emissive, Resource weight) {
    res.publish(position, b.position);
    res.publish(normal, b.normal);
    res.publish(albedo, b.albedo);
    res.publish(emissive, b.emissive);
    res.publish(weight, b.weight);
}

void declare(PassBuilder& b, Resource position, Resource normal, Resource albedo, Resource emissive,
             Resource weight) {
    b.create(position, {GL_RGBA32F, SizeRule::Canvas, Storage::PassOwned});
    for (Resource r : {normal, albedo, emissive, weight})
        b.create(r, {GL_RGBA16F, SizeRule::Canvas, Storage::PassOwned});
}

}  // namespace

SpecularGBufferPass::SpecularGBufferPass(bool prepareHalfPrograms)
    : programs_{fullscreenProgram("specular gbuffer (reflection)",
                                  "passes/specular/specular_gbuffer.frag",
                                  "#define MIRAGE_SPECULAR_MODE 0"),
                fullscreenProgram("specular gbuffer (refraction)",
                                  "passes/specular/specular_gbuffer.frag",
                                  "#define MIRAGE_SPECULAR_MODE 1")} {
    if (prepareHalfPrograms) buildHalfPrograms();
}

void SpecularGBufferPass::setup(PassBuilder& b) const {
    for (Resource r : {kGBufferPosition, kGBufferNormal, kGBufferEmissive, kBackFacePosition,
                       kBackFaceNormal, kSpecularMask})
        b.read(r);
    ImpostorPass::declareTracing(b);
    declare(b, kReflectionGBuffer, kReflectionNormal, kReflectionAlbedo, kReflectionEmissive,
            kReflectionWeight);
    declare(b, kRefractionGBuffer, kRefractionNormal, kRefractionAlbedo, kRefractionEmissive,
            kRefractionWeight);
}

PassDecision SpecularGBufferPass::decide(const FrameContext& ctx) const {
    return {true, std::to_string(ctx.scene.specularDraws().size()) +
                      " specular draw(s): reflected and refracted rays"};
}

void SpecularGBufferPass::resize(const FrameContext& ctx) {
    const int w = ctx.canvasWidth(), h = ctx.canvasHeight();
    if (w == width_ && h == height_) return;
    width_ = w;
    height_ = h;
    allocate(refl_, "GBuf_refl", w, h);
    allocate(refr_, "GBuf_refr", w, h);
    attachedMask_ = 0;
    halfWidth_ = halfHeight_ = 0;  // the half-resolution buffers follow on first use
}

void SpecularGBufferPass::allocateHalfResolution() {
    halfWidth_ = (width_ + 1) / 2;
    halfHeight_ = (height_ + 1) / 2;
    allocate(halfRefl_, "half GBuf_refl", halfWidth_, halfHeight_);
    allocate(halfRefr_, "half GBuf_refr", halfWidth_, halfHeight_);
    halfMask_ = gl::Texture::create2D("half specular block mask", halfWidth_, halfHeight_,
                                      GL_DEPTH_COMPONENT32F);
    halfMaskFbo_ = gl::Framebuffer("half specular block mask fbo");
    halfMaskFbo_.attachDepth(halfMask_);
    halfMaskFbo_.finalize(0);
    halfMaskDrawn_.markAll();
    for (SpecularHitBuffer* hits : {&halfRefl_, &halfRefr_}) {
        hits->fbo.attachDepth(halfMask_);
        hits->fbo.finalize(5);
    }
    buildHalfPrograms();
}

// The half-resolution trace's programs (kept across resizes; built once).
void SpecularGBufferPass::buildHalfPrograms() {
    if (halfPrograms_[0].id() != 0) return;
    for (int mode = 0; mode < 2; ++mode) {
        const std::string defines = "#define MIRAGE_SPECULAR_MODE " + std::to_string(mode) + "\n";
        const std::string what = mode == 0 ? " (reflection)" : " (refraction)";
        halfPrograms_[mode] = fullscreenProgram("specular gbuffer, half resolution" + what,
                                                "passes/specular/specular_gbuffer.frag",
                                                defines + "#define MIRAGE_SPECULAR_TRACE_HALF 1\n");
        fillPrograms_[mode] = fullscreenProgram(
            "specular gbuffer fill" + what, "passes/specular/specular_trace_fill.frag", defines);
    }
    halfMaskProgram_ = fullscreenProgram("specular half-resolution mask",
                                         "passes/specular/specular_half_mask.frag");
}

void SpecularGBufferPass::execute(FrameContext& ctx, PassResources& res) {
    ctx.scene.bindTableTexels(sceneTables_, kUnitSpecGbufMaterials, kUnitSpecGbufSpecularDraws);
    glBindTextureUnit(kUnitSpecGbufPosition, res.texture(kGBufferPosition).id());
    glBindTextureUnit(kUnitSpecGbufNormal, res.texture(kGBufferNormal).id());
    glBindTextureUnit(kUnitSpecGbufEmissive, res.texture(kGBufferEmissive).id());
    glBindTextureUnit(kUnitSpecGbufBackPosition, res.texture(kBackFacePosition).id());
    glBindTextureUnit(kUnitSpecGbufBackNormal, res.texture(kBackFaceNormal).id());
    ImpostorPass::bindForTracing(res, impostorTables_);  // kUnitImpostor*, the header block
    // The G-buffer pass's specular-pixel mask as both hit buffers' depth (it reallocates it only
    // on a resize).
    const gl::Texture& mask = res.texture(kSpecularMask);
    if (mask.id() != attachedMask_) {
        for (SpecularHitBuffer* hits : {&refl_, &refr_}) {
            hits->fbo.attachDepth(mask);
            hits->fbo.finalize(5);
        }
        attachedMask_ = mask.id();
    }
    if (ctx.options.specular.halfResolutionTrace)
        traceHalfResolution(ctx, res);
    else
        traceFullResolution(ctx);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    glDisable(GL_DEPTH_TEST);
    publish(res, refl_, kReflectionGBuffer, kReflectionNormal, kReflectionAlbedo,
            kReflectionEmissive, kReflectionWeight);
    publish(res, refr_, kRefractionGBuffer, kRefractionNormal, kRefractionAlbedo,
            kRefractionEmissive, kRefractionWeight);
}

namespace {
// One trace (mode 0: the reflection, 1: the refraction) of `program` into `hits`, a width x
// height target, over `rects`: only specular pixels pass the early depth test (the triangle lies
// at depth 0.5 against the mask); the rest of the rectangles is cleared to 0 (no specular pixel,
// or none that refracts).
void trace(FrameContext& ctx, int mode, const gl::Program& program, SpecularHitBuffer& hits,
           int width, int height, const std::vector<glm::ivec4>& rects) {
    hits.fbo.bind();
    ctx.beginFullscreen(program, width, height);
    if (mode == 1)
        glUniform1i(program.uniformLocation("marchSteps"),
                    ctx.options.specular.refractionMarchSteps);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_FALSE);
    ctx.clearForRects(rects, hits.drawn, 0, 5);
    ctx.drawFullscreenTriangleIn(rects);
}
}  // namespace

void SpecularGBufferPass::traceFullResolution(FrameContext& ctx) {
    for (int mode = 0; mode < 2; ++mode)
        trace(ctx, mode, programs_[mode], mode == 0 ? refl_ : refr_, ctx.canvasWidth(),
              ctx.canvasHeight(), mode == 0 ? ctx.specularRects : ctx.refractiveRects);
}

namespace {
// Canvas rectangles in half pixels (2x2 blocks), rounded outwards.
std::vector<glm::ivec4> halfRects(const std::vector<glm::ivec4>& rects) {
    std::vector<glm::ivec4> out;
    for (const glm::ivec4& s : rects)
        out.push_back(
            {s.x / 2, s.y / 2, (s.x + s.z + 1) / 2 - s.x / 2, (s.y + s.w + 1) / 2 - s.y / 2});
    return mergeOverlappingRects(std::move(out));
}
}  // namespace

void SpecularGBufferPass::traceHalfResolution(FrameContext& ctx, PassResources& res) {
    if (halfWidth_ == 0) allocateHalfResolution();
    // The blocks holding a specular pixel (depth 0; specular_half_mask.frag reads the flag from
    // the primary G-buffer's emissive alpha, the specular slot + 1).
    const std::vector<glm::ivec4> blocks = halfRects(ctx.specularRects);
    halfMaskFbo_.bind();
    ctx.beginFullscreen(halfMaskProgram_, halfWidth_, halfHeight_);
    glBindTextureUnit(kUnitSpecLightReflFirst + 3, res.texture(kGBufferEmissive).id());
    glDepthMask(GL_TRUE);
    ctx.clearForRects(blocks, halfMaskDrawn_, 0, 0, true);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_ALWAYS);
    ctx.drawFullscreenTriangleIn(blocks);
    // The trace's units again (the mask's shared one). The refraction only in the glass objects'
    // blocks (the fill reads it there only).
    glBindTextureUnit(kUnitSpecGbufBackPosition, res.texture(kBackFacePosition).id());
    const std::vector<glm::ivec4> glassBlocks = halfRects(ctx.refractiveRects);
    for (int mode = 0; mode < 2; ++mode)
        trace(ctx, mode, halfPrograms_[mode], mode == 0 ? halfRefl_ : halfRefr_, halfWidth_,
              halfHeight_, mode == 0 ? blocks : glassBlocks);
    // The fill, on the canvas's specular pixels.
    const gl::Texture* half[10] = {&halfRefl_.position, &halfRefl_.normal, &halfRefl_.albedo,
                                   &halfRefl_.emissive, &halfRefl_.weight, &halfRefr_.position,
                                   &halfRefr_.normal,   &halfRefr_.albedo, &halfRefr_.emissive,
                                   &halfRefr_.weight};
    for (int mode = 0; mode < 2; ++mode) {
        SpecularHitBuffer& hits = mode == 0 ? refl_ : refr_;
        hits.fbo.bind();
        ctx.beginFullscreen(fillPrograms_[mode], ctx.canvasWidth(), ctx.canvasHeight());
        for (int i = 0; i < 10; ++i)
            glBindTextureUnit(GLuint(kUnitSpecFillHalfFirst + i), half[i]->id());
        glBindTextureUnit(kUnitSpecFillPosition, res.texture(kGBufferPosition).id());
        glBindTextureUnit(kUnitSpecFillNormal, res.texture(kGBufferNormal).id());
        glBindTextureUnit(kUnitSpecFillEmissive, res.texture(kGBufferEmissive).id());
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_GREATER);
        glDepthMask(GL_FALSE);
        const std::vector<glm::ivec4>& rects = mode == 0 ? ctx.specularRects : ctx.refractiveRects;
        ctx.clearForRects(rects, hits.drawn, 0, 5);
        ctx.drawFullscreenTriangleIn(rects);
    }
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeSpecularGBufferPass(const PassInit& init) {
    const SpecularOptions& o = init.options.specular;
    return std::make_unique<SpecularGBufferPass>(o.halfResolutionTrace ||
                                                 o.prepareGovernedVariants);
}

}  // namespace mirage::render
