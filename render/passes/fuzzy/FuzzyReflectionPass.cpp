#include "render/passes/fuzzy/FuzzyReflectionPass.h"

#include <cmath>

#include <fmt/format.h>

#include "render/FrameGraph.h"
#include "render/FrameImports.h"
#include "render/PassRegistry.h"
#include "render/passes/gbuffer/GBufferPass.h"
#include "render/passes/specular/SpecularGBufferPass.h"
#include "render/passes/specular/SpecularLightPass.h"

namespace mirage::render {
namespace {
// The buffers this pass writes a new version of (filtered on rough pixels, passed through
// elsewhere), in the filter's input order; the fifth input is the video term it creates.
constexpr Resource kFiltered[4] = {kSpecularRv, kSpecularR, kSpecularRReflection, kLenv};
constexpr float kPi = 3.14159265358979f;

void attachAll(gl::Framebuffer& fbo, gl::Texture (&t)[5]) {
    for (int i = 0; i < 5; ++i) fbo.attachColor(i, t[i]);
    fbo.finalize(5);
}
}  // namespace

FuzzyReflectionPass::FuzzyReflectionPass()
    : resolve_(fullscreenProgram("fuzzy resolve", "passes/fuzzy/fuzzy_resolve.frag")),
      filter_(fullscreenProgram("fuzzy filter", "passes/fuzzy/fuzzy_filter.frag")) {
    locEpsilon_ = resolve_.uniformLocation("depthEpsilon");
    locGlassResolve_ = resolve_.uniformLocation("filterGlass");
    locGlassFilter_ = filter_.uniformLocation("filterGlass");
    locStep_ = filter_.uniformLocation("stepDir");
    locCone_ = filter_.uniformLocation("coneBound");
    locFocal_ = filter_.uniformLocation("focalPx");
    locTaps_ = filter_.uniformLocation("taps");
}

void FuzzyReflectionPass::setup(PassBuilder& b) const {
    for (Resource r :
         {kGBufferPosition, kGBufferNormal, kGBufferEmissive, kReflectionGBuffer, kReflectionWeight,
          kRefractionGBuffer, kRefractionWeight, kRealSurfaces, kCameraImage})
        b.read(r);
    // In float32, as the L' buffers come and as the composite computes the video term for a
    // sharp pixel: a kernel of one pixel then reproduces the mirror path exactly.
    for (Resource r : kFiltered) b.modify(r, {GL_RGBA32F, SizeRule::Canvas, Storage::PassOwned});
    b.create(kFilteredVideo, {GL_RGBA32F, SizeRule::Canvas, Storage::PassOwned});
}

PassDecision FuzzyReflectionPass::decide(const FrameContext& ctx) const {
    // Rough glass is this pass's only with rough_method=filter (else render/passes/rough).
    const bool filterGlass = ctx.options.rough.method == RoughRefractionMethod::Filter;
    const int metals = ctx.scene.roughReflectorCount(),
              glass = filterGlass ? ctx.scene.roughGlassCount() : 0;
    if (metals == 0 && glass == 0 && ctx.scene.roughGlassCount() > 0)
        return {false, fmt::format("no rough metal; rough glass by rough_method={}",
                                   roughRefractionMethodName(ctx.options.rough.method))};
    if (metals + glass == 0)
        return {false,
                fmt::format("no rough metal (roughness {} .. {}) or rough glass",
                            Material::kMirrorMaxRoughness, Material::kRoughReflectorMaxRoughness)};
    if (!ctx.options.fuzzy.enabled)
        return {false, "fuzzy filter off: rough metals and glass render as smooth"};
    return {true, fmt::format("{} rough metal(s), {} rough glass: cone {:g} deg, separable, {} "
                              "taps per side",
                              metals, glass, ctx.options.fuzzy.coneDeg, ctx.options.fuzzy.taps)};
}

void FuzzyReflectionPass::resize(const FrameContext& ctx) {
    const int w = ctx.canvasWidth(), h = ctx.canvasHeight();
    if (w == width_ && h == height_) return;
    width_ = w;
    height_ = h;
    video_ = gl::Texture::create2D("fuzzy video term", w, h, GL_RGBA32F);
    static const char* names[5] = {"L'_rv", "L'_r", "L'_r reflection share", "L_env", "video"};
    for (int i = 0; i < 5; ++i) {
        rows_[i] = gl::Texture::create2D(std::string("fuzzy rows ") + names[i], w, h, GL_RGBA32F);
        out_[i] = gl::Texture::create2D(std::string("fuzzy ") + names[i], w, h, GL_RGBA32F);
    }
    videoFbo_ = gl::Framebuffer("fuzzy video fbo");
    videoFbo_.attachColor(0, video_);
    videoFbo_.finalize(1);
    rowsFbo_ = gl::Framebuffer("fuzzy rows fbo");
    attachAll(rowsFbo_, rows_);
    outFbo_ = gl::Framebuffer("fuzzy fbo");
    attachAll(outFbo_, out_);
    for (DrawnRects* d : {&videoDrawn_, &rowsDrawn_, &outDrawn_}) d->markAll();
    const std::vector<glm::vec2> table = ctx.projection.canvasToCameraTable();
    canvasToCamera_ = gl::Texture::create2D("fuzzy canvas to camera", w, h, GL_RG32F);
    canvasToCamera_.setFilter(GL_LINEAR, GL_LINEAR);
    canvasToCamera_.upload(GL_RG, GL_FLOAT, table.data());
}

void FuzzyReflectionPass::execute(FrameContext& ctx, PassResources& res) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingMaterials, ctx.scene.materialBuffer().id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingSpecularDraws,
                     ctx.scene.specularDrawBuffer().id());
    glBindTextureUnit(kUnitFuzzyPosition, res.texture(kGBufferPosition).id());
    glBindTextureUnit(kUnitFuzzyEmissive, res.texture(kGBufferEmissive).id());
    glBindTextureUnit(kUnitFuzzyReflHit, res.texture(kReflectionGBuffer).id());
    glBindTextureUnit(kUnitFuzzyReflWeight, res.texture(kReflectionWeight).id());
    glBindTextureUnit(kUnitFuzzyCamera, res.texture(kCameraImage).id());
    glBindTextureUnit(kUnitFuzzyRealSurfaces, res.texture(kRealSurfaces).id());
    glBindTextureUnit(kUnitFuzzyCanvasToCamera, canvasToCamera_.id());
    glBindTextureUnit(kUnitFuzzySpecRRefl, res.texture(kSpecularRReflection).id());
    glBindTextureUnit(kUnitFuzzySpecR, res.texture(kSpecularR).id());
    glBindTextureUnit(kUnitFuzzyRefrHit, res.texture(kRefractionGBuffer).id());
    glBindTextureUnit(kUnitFuzzyRefrWeight, res.texture(kRefractionWeight).id());
    glBindTextureUnit(kUnitFuzzyNormal, res.texture(kGBufferNormal).id());
    const int w = ctx.canvasWidth(), h = ctx.canvasHeight();

    // 1. The reflection's video term per rough pixel (the composite's back-projection).
    videoFbo_.bind();
    ctx.beginFullscreen(resolve_, w, h);
    glUniform1f(locEpsilon_, ctx.options.specular.backProjectionEpsilon);
    const int filterGlass = ctx.options.rough.method == RoughRefractionMethod::Filter ? 1 : 0;
    glUniform1i(locGlassResolve_, filterGlass);
    // The filters read neighbours anywhere in the rectangle around every specular object.
    const std::vector<glm::ivec4> rect{ctx.specularScissor};
    ctx.clearForRects(rect, videoDrawn_, 0, 1);
    ctx.drawFullscreenTriangleIn(rect);

    // 2. Rows, then columns of the rows' result. The canvas has the camera's focal lengths
    // (pixels per radian near the axis: Eq. 5's image size / view angle).
    const float focalPx = float(0.5 * (ctx.projection.camera.fx + ctx.projection.camera.fy));
    const float cone = ctx.options.fuzzy.coneDeg * kPi / 180.0f;
    for (int pass = 0; pass < 2; ++pass) {
        (pass == 0 ? rowsFbo_ : outFbo_).bind();
        ctx.beginFullscreen(filter_, w, h);
        for (int i = 0; i < 5; ++i) {
            const gl::Texture& in = pass == 1 ? rows_[i]
                                    : i < 4   ? res.texture(kFiltered[i])
                                              : video_;
            glBindTextureUnit(GLuint(kUnitFuzzyInputFirst + i), in.id());
        }
        glUniform2i(locStep_, pass == 0 ? 1 : 0, pass == 0 ? 0 : 1);
        glUniform1f(locCone_, cone);
        glUniform1f(locFocal_, focalPx);
        glUniform1i(locTaps_, ctx.options.fuzzy.taps);
        glUniform1i(locGlassFilter_, filterGlass);
        ctx.clearForRects(rect, pass == 0 ? rowsDrawn_ : outDrawn_, 0, 5);
        ctx.drawFullscreenTriangleIn(rect);
    }
    for (int i = 0; i < 4; ++i) res.publish(kFiltered[i], out_[i]);
    res.publish(kFilteredVideo, out_[4]);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeFuzzyReflectionPass(const PassInit&) {
    return std::make_unique<FuzzyReflectionPass>();
}

}  // namespace mirage::render
