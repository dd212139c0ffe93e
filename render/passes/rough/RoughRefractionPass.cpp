#include "render/passes/rough/RoughRefractionPass.h"

#include <algorithm>

#include <fmt/format.h>

#include "render/FrameGraph.h"
#include "render/FrameImports.h"
#include "render/PassRegistry.h"
#include "render/passes/backface/BackFacePass.h"
#include "render/passes/fuzzy/FuzzyReflectionPass.h"
#include "render/passes/gbuffer/GBufferPass.h"
#include "render/passes/specular/SpecularGBufferPass.h"
#include "render/passes/specular/SpecularLightPass.h"

namespace mirage::render {
namespace {
// The buffers this pass writes a new version of (rough glass filtered, every other pixel passed
// through from the version before: the fuzzy pass's, or the specular light pass's).
constexpr Resource kFiltered[4] = {kSpecularRv, kSpecularR, kSpecularRReflection, kLenv};
static_assert(kUnitRoughPrefilteredFirst == kUnitRoughLeanFirst + 3);

int fullChain(int w, int h) {
    int levels = 1;
    while ((std::max(w, h) >> levels) > 0) ++levels;
    return levels;
}
}  // namespace

RoughRefractionPass::RoughRefractionPass()
    : prefilter_(fullscreenProgram("rough prefilter", "passes/rough/rough_prefilter.frag")),
      refraction_(fullscreenProgram("rough refraction", "passes/rough/rough_refraction.frag")) {
    locPrefilterEpsilon_ = prefilter_.uniformLocation("depthEpsilon");
    locMethod_ = refraction_.uniformLocation("method");
    locSubdivisions_ = refraction_.uniformLocation("subdivisions");
    locFocal_ = refraction_.uniformLocation("focalPx");
    locMaxLevel_ = refraction_.uniformLocation("maxLevel");
    locFootprint_ = refraction_.uniformLocation("footprintModel");
}

void RoughRefractionPass::setup(PassBuilder& b) const {
    for (Resource r : {kGBufferPosition, kGBufferNormal, kGBufferEmissive, kReflectionGBuffer,
                       kReflectionWeight, kRefractionGBuffer, kRefractionWeight, kRealSurfaces,
                       kCameraImage, kBackFacePosition, kBackFaceNormal})
        b.read(r);
    // In float32 as the L' buffers come and as the fuzzy pass's: the limit of a one-texel lobe
    // reproduces the smooth path exactly. The video term is the fuzzy pass's when it ran (rough
    // metals filtered in the same frame), else made here.
    for (Resource r : kFiltered) b.modify(r, {GL_RGBA32F, SizeRule::Canvas, Storage::PassOwned});
    b.modifyOptional(kFilteredVideo, {GL_RGBA32F, SizeRule::Canvas, Storage::PassOwned});
}

PassDecision RoughRefractionPass::decide(const FrameContext& ctx) const {
    const int glass = ctx.scene.roughGlassCount();
    if (glass == 0)
        return {false,
                fmt::format("no rough glass (roughness above {})", Material::kMirrorMaxRoughness)};
    const RendererOptions& o = ctx.options;
    if (o.rough.method == RoughRefractionMethod::Filter)
        return {false, "rough glass by the fuzzy pass's image-space filter (rough_method=filter)"};
    if (o.rough.method == RoughRefractionMethod::Gsr)
        return {true, fmt::format("{} rough glass: GSR, {} hemisphere subdivisions, {} mip levels",
                                  glass, o.rough.gsrSubdivisions, o.rough.mipLevels)};
    return {true, fmt::format("{} rough glass: LEAN, {} mip levels", glass, o.rough.mipLevels)};
}

void RoughRefractionPass::resize(const FrameContext& ctx) {
    const int w = ctx.canvasWidth(), h = ctx.canvasHeight();
    const int levels = std::min(ctx.options.rough.mipLevels, fullChain(w, h));
    if (w == width_ && h == height_ && levels == levels_) return;
    width_ = w;
    height_ = h;
    levels_ = levels;
    static const char* chainNames[kChains] = {"LEAN mean",         "LEAN squares",
                                              "LEAN products",     "prefiltered L'_rv",
                                              "prefiltered L'_r",  "prefiltered reflection share",
                                              "prefiltered L_env", "prefiltered video term"};
    chainsFbo_ = gl::Framebuffer("rough chains fbo");
    for (int i = 0; i < kChains; ++i) {
        // In float32: the moments (the covariance is a difference of them), the L' buffers as
        // they come (the one-texel limit is exact) and the video term as the composite's.
        chains_[i] =
            gl::Texture::create2D(std::string("rough ") + chainNames[i], w, h, GL_RGBA32F, levels);
        chains_[i].setFilter(GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR);
        chains_[i].setWrap(GL_CLAMP_TO_EDGE);
        chainsFbo_.attachColor(i, chains_[i]);
    }
    chainsFbo_.finalize(kChains);
    static const char* names[5] = {"L'_rv", "L'_r", "L'_r reflection share", "L_env", "video"};
    outFbo_ = gl::Framebuffer("rough refraction fbo");
    for (int i = 0; i < 5; ++i) {
        out_[i] = gl::Texture::create2D(std::string("rough ") + names[i], w, h, GL_RGBA32F);
        outFbo_.attachColor(i, out_[i]);
    }
    outFbo_.finalize(5);
    chainsDrawn_.markAll();
    outDrawn_.markAll();
    const std::vector<glm::vec2> table = ctx.projection.canvasToCameraTable();
    canvasToCamera_ = gl::Texture::create2D("rough canvas to camera", w, h, GL_RG32F);
    canvasToCamera_.setFilter(GL_LINEAR, GL_LINEAR);
    canvasToCamera_.upload(GL_RG, GL_FLOAT, table.data());
}

void RoughRefractionPass::execute(FrameContext& ctx, PassResources& res) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingMaterials, ctx.scene.materialBuffer().id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingSpecularDraws,
                     ctx.scene.specularDrawBuffer().id());
    const int w = ctx.canvasWidth(), h = ctx.canvasHeight();
    glBindTextureUnit(kUnitRoughPosition, res.texture(kGBufferPosition).id());
    glBindTextureUnit(kUnitRoughNormal, res.texture(kGBufferNormal).id());
    glBindTextureUnit(kUnitRoughEmissive, res.texture(kGBufferEmissive).id());
    glBindTextureUnit(kUnitRoughReflHit, res.texture(kReflectionGBuffer).id());
    glBindTextureUnit(kUnitRoughReflWeight, res.texture(kReflectionWeight).id());
    glBindTextureUnit(kUnitRoughRefrHit, res.texture(kRefractionGBuffer).id());
    glBindTextureUnit(kUnitRoughRefrWeight, res.texture(kRefractionWeight).id());
    glBindTextureUnit(kUnitRoughRealSurfaces, res.texture(kRealSurfaces).id());
    glBindTextureUnit(kUnitRoughCanvasToCamera, canvasToCamera_.id());
    glBindTextureUnit(kUnitRoughCamera, res.texture(kCameraImage).id());
    glBindTextureUnit(kUnitRoughBackPosition, res.texture(kBackFacePosition).id());
    glBindTextureUnit(kUnitRoughBackNormal, res.texture(kBackFaceNormal).id());
    for (int i = 0; i < 4; ++i)
        glBindTextureUnit(GLuint(kUnitRoughSpecFirst + i), res.texture(kFiltered[i]).id());

    // 1. Level 0 of the chains over the specular rectangle (zero elsewhere: no coverage), then
    // the box-filtered levels.
    chainsFbo_.bind();
    ctx.beginFullscreen(prefilter_, w, h);
    glUniform1f(locPrefilterEpsilon_, ctx.options.specular.backProjectionEpsilon);
    const std::vector<glm::ivec4> rect{ctx.specularScissor};
    ctx.clearForRects(rect, chainsDrawn_, 0, kChains);
    ctx.drawFullscreenTriangleIn(rect);
    for (gl::Texture& t : chains_) glGenerateTextureMipmap(t.id());

    // 2. The lobes per rough-glass pixel.
    for (int i = 0; i < kChains; ++i)
        glBindTextureUnit(GLuint(kUnitRoughLeanFirst + i), chains_[i].id());
    for (int i = 0; i < 5; ++i) {
        const gl::Texture& in =
            i < 4 ? res.texture(kFiltered[i]) : res.textureOr(kFilteredVideo, ctx.blackTexture());
        glBindTextureUnit(GLuint(kUnitRoughInputFirst + i), in.id());
    }
    outFbo_.bind();
    ctx.beginFullscreen(refraction_, w, h);
    glUniform1i(locMethod_, ctx.options.rough.method == RoughRefractionMethod::Gsr ? 1 : 0);
    glUniform1i(locSubdivisions_, ctx.options.rough.gsrSubdivisions);
    const CameraIntrinsics& K = ctx.projection.camera;
    glUniform1f(locFocal_, float(0.5 * (K.fx + K.fy)));
    glUniform1f(locMaxLevel_, float(levels_ - 1));
    glUniform1i(locFootprint_, ctx.options.rough.rayDifferentials ? 1 : 0);
    ctx.clearForRects(rect, outDrawn_, 0, 5);
    ctx.drawFullscreenTriangleIn(rect);
    for (int i = 0; i < 4; ++i) res.publish(kFiltered[i], out_[i]);
    res.publish(kFilteredVideo, out_[4]);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeRoughRefractionPass(const PassInit&) {
    return std::make_unique<RoughRefractionPass>();
}

}  // namespace mirage::render
