#include "render/passes/composite/CompositePass.h"

#include <array>
#include <cmath>

#include "render/FrameGraph.h"
#include "render/FrameImports.h"
#include "render/PassRegistry.h"
#include "render/passes/backface/BackFacePass.h"
#include "render/passes/caustic/CausticPass.h"
#include "render/passes/direct/DirectLightPass.h"
#include "render/passes/environment/EnvironmentPass.h"
#include "render/passes/exposure/ExposurePass.h"
#include "render/passes/fuzzy/FuzzyReflectionPass.h"
#include "render/passes/gbuffer/GBufferPass.h"
#include "render/passes/specular/SpecularGBufferPass.h"
#include "render/passes/specular/SpecularLightPass.h"
#include "render/passes/translucency/TranslucencyPass.h"

namespace mirage::render {
namespace {
// L'_rv, L'_r, its reflection share and L_env at their newest version: the specular light
// pass's, or the fuzzy / rough passes' filtered ones (equal to it outside their pixels).
constexpr Resource kSpecularBuffers[4] = {kSpecularRv, kSpecularR, kSpecularRReflection, kLenv};
static_assert(kUnitCompositeFuzzyVideo == kUnitCompositeFuzzyRv + 4);
}  // namespace

const CompositePass::SpecularVariant& CompositePass::specularVariant(SpecularKind kind) {
    SpecularVariant& v = specular_[kind];
    if (v.program.id() != 0) return v;
    static const char* const kLabels[kSpecularKinds] = {"composite", "composite (first exit only)",
                                                        "composite (reflection only)"};
    static const char* const kDefines[kSpecularKinds] = {"", "#define MIRAGE_NO_SECOND_EXIT 1\n",
                                                         "#define MIRAGE_REFLECTION_ONLY 1\n"};
    v.program = fullscreenProgram(kLabels[kind], "passes/composite/composite.frag",
                                  identityDefine_ + kDefines[kind]);
    v.epsilon = v.program.uniformLocation("depthEpsilon");
    v.showVirtual = v.program.uniformLocation("showVirtual");
    v.withCaustics = v.program.uniformLocation("withCaustics");
    v.secondExit = v.program.uniformLocation("secondExitOn");
    v.fuzzyOn = v.program.uniformLocation("fuzzyOn");
    v.denoiseFootage = v.program.uniformLocation("denoiseFootage");
    v.noiseVariance = v.program.uniformLocation("noiseVariance");
    return v;
}

void CompositePass::buildPrograms(const FrameContext& ctx, bool identityRemap,
                                  bool translucentReflection) {
    // Without lens distortion on a canvas of the camera's size the remap is the identity: the
    // variant reads each buffer at its own pixel instead of looking the position up and
    // filtering (on llvmpipe a bilinear read costs four, and the table read one more).
    const std::string identity = identityRemap ? "#define MIRAGE_IDENTITY_REMAP 1\n" : "";
    identityDefine_ = identity;
    for (SpecularVariant& v : specular_) v = SpecularVariant{};
    bool glass = false, mirror = false;
    for (int i : ctx.scene.specularDraws()) {
        const bool transmissive = ctx.scene.draws()[size_t(i)].transmissive;
        glass = glass || transmissive;
        mirror = mirror || !transmissive;
    }
    const SpecularOptions& so = ctx.options.specular;
    if (glass && (so.secondExit || so.prepareGovernedVariants)) specularVariant(kGlass);
    if (glass && (!so.secondExit || so.prepareGovernedVariants))
        specularVariant(kGlassFirstExitOnly);
    if (mirror) specularVariant(kReflectionOnly);
    programDiffuse_ =
        fullscreenProgram("composite (diffuse only)", "passes/composite/composite.frag",
                          identity + "#define MIRAGE_DIFFUSE_ONLY 1\n");
    programDiffuseNoCaustics_ = fullscreenProgram(
        "composite (diffuse only, no caustics)", "passes/composite/composite.frag",
        identity + "#define MIRAGE_DIFFUSE_ONLY 1\n#define MIRAGE_NO_CAUSTICS 1\n");
    if (translucentReflection) {
        programTranslucent_ = fullscreenProgram(
            "composite (translucent pixels, with the boundary's reflection)",
            "passes/composite/composite.frag",
            identity + "#define MIRAGE_DIFFUSE_ONLY 1\n#define MIRAGE_TRANSLUCENT_REFLECTION 1\n");
        locShowVirtualTranslucent_ = programTranslucent_.uniformLocation("showVirtual");
        locWithCausticsTranslucent_ = programTranslucent_.uniformLocation("withCaustics");
    }
    maskProgram_ = fullscreenProgram("composite specular mask",
                                     "passes/composite/composite_mask.frag", identity);
    locShowVirtualDiffuse_ = programDiffuse_.uniformLocation("showVirtual");
    locWithCausticsDiffuse_ = programDiffuse_.uniformLocation("withCaustics");
    locShowVirtualNoCaustics_ = programDiffuseNoCaustics_.uniformLocation("showVirtual");
    identityRemap_ = identityRemap;
    translucentReflection_ = translucentReflection;
    programsBuilt_ = true;
}

bool CompositePass::isIdentityRemap(const CameraProjection& p) {
    const int w = p.camera.width, h = p.camera.height;
    if (p.canvasWidth != w || p.canvasHeight != h || p.remap.size() != size_t(w) * size_t(h))
        return false;
    // Within a thousandth of a pixel: the bilinear weights the general variant would use are 0
    // and 1 to that precision.
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const glm::vec2 q = p.remap[size_t(y) * size_t(w) + size_t(x)];
            if (std::abs(q.x - float(x)) > 1e-3f || std::abs(q.y - float(y)) > 1e-3f) return false;
        }
    return true;
}

void CompositePass::setup(PassBuilder& b) const {
    b.read(kCameraImage);
    // The two GI solutions (direct light alone when no VPL light was filtered into them).
    b.read(kLRv);
    b.read(kLR);
    for (Resource r : {kCausticRv, kCausticR, kGBufferPosition}) b.readOptional(r);
    // Translucent pixels' reflection (the mirror ray marched over the G-buffer): its normals
    // and the IOR the emissive buffer's alpha holds.
    for (Resource r : {kGBufferNormal, kTranslucentRadiance}) b.readOptional(r);
    // Mirror / glass pixels (Eqs. 6-11): only when the specular passes ran.
    for (Resource r :
         {kGBufferEmissive, kReflectionGBuffer, kRefractionGBuffer, kReflectionWeight,
          kRefractionWeight, kSpecularRv, kSpecularR, kSpecularRReflection, kLenv, kRealSurfaces})
        b.readOptional(r);
    // Rough metals and glass: the filtered video term, when the fuzzy or rough pass ran.
    b.readOptional(kFilteredVideo);
    // Glass: the refracted path's second exit (second_exit.glsl) marches the back faces and
    // looks the environment up.
    for (Resource r : {kBackFacePosition, kBackFaceNormal, kEnvironmentMap}) b.readOptional(r);
    // The per-frame exposure (passes/exposure): its gain reaches this pass through the frame
    // block; the read keeps the exposure pass in the frame when it is switched on.
    b.readOptional(kExposureSamples);
    b.create(kComposite, {GL_RGBA32F, SizeRule::Camera, Storage::PassOwned});
    b.create(kCompositeSrgb, {GL_SRGB8_ALPHA8, SizeRule::Camera, Storage::PassOwned});
    b.create(kCompositeFootage, {GL_RGBA16F, SizeRule::Camera, Storage::PassOwned});
}

PassDecision CompositePass::decide(const FrameContext&) const {
    return {true, "always: the output image"};
}

void CompositePass::resize(const FrameContext& ctx) {
    const CameraProjection& p = ctx.projection;
    const int w = p.camera.width, h = p.camera.height;
    // Runs before every frame; the camera (and so the remap tables) is fixed for the renderer's
    // life, so only a size change rebuilds them (the programs also follow the option).
    const bool sameSize = linear_.width() == w && linear_.height() == h &&
                          canvasToCamera_.width() == p.canvasWidth &&
                          canvasToCamera_.height() == p.canvasHeight;
    if (!sameSize) remapIsIdentity_ = isIdentityRemap(p);
    const bool identity = ctx.options.composite.identityRemap && remapIsIdentity_;
    bool translucent = false;
    for (const DrawItem& d : ctx.scene.draws()) translucent = translucent || d.translucent;
    const bool reflection = translucent && ctx.options.translucency.enabled &&
                            ctx.options.translucency.surfaceReflection;
    if (!programsBuilt_ || identity != identityRemap_ || reflection != translucentReflection_)
        buildPrograms(ctx, identity, reflection);
    if (sameSize) return;
    linear_ = gl::Texture::create2D("composite linear", w, h, GL_RGBA32F);
    srgb_ = gl::Texture::create2D("composite srgb", w, h, GL_SRGB8_ALPHA8);
    remap_ = gl::Texture::create2D("lens remap", w, h, GL_RG32F);
    remap_.setFilter(GL_NEAREST, GL_NEAREST);
    remap_.upload(GL_RG, GL_FLOAT, p.remap.data());
    {
        std::vector<glm::vec2> table = p.canvasToCameraTable();
        canvasToCamera_ =
            gl::Texture::create2D("canvas to camera", p.canvasWidth, p.canvasHeight, GL_RG32F);
        canvasToCamera_.setFilter(GL_LINEAR, GL_LINEAR);
        canvasToCamera_.upload(GL_RG, GL_FLOAT, table.data());
        canvasToCameraTable_ = std::move(table);
    }
    footage_ = gl::Texture::create2D("composite footage", w, h, GL_RGBA16F);
    fbo_ = gl::Framebuffer("composite fbo");
    fbo_.attachColor(0, linear_);
    fbo_.attachColor(1, srgb_);
    // The footage target only while the motion blur or the vignetting reads it (the options are
    // the renderer's for its whole life): otherwise the shader's third output goes nowhere.
    const bool footage = ctx.options.motionBlur.enabled() || ctx.options.grain.vignette.enabled;
    if (footage) fbo_.attachColor(2, footage_);
    mask_ = gl::Texture::create2D("composite specular mask", w, h, GL_DEPTH_COMPONENT32F);
    fbo_.attachDepth(mask_);
    fbo_.finalize(footage ? 3 : 2);
    maskFbo_ = gl::Framebuffer("composite specular mask fbo");
    maskFbo_.attachDepth(mask_);
    maskFbo_.finalize(0);
    maskDrawn_.markAll();
}

glm::ivec4 CompositePass::cameraRect(const FrameContext& ctx, const glm::ivec4& canvasRect) const {
    const int w = ctx.projection.camera.width, h = ctx.projection.camera.height;
    const int cw = ctx.canvasWidth(), ch = ctx.canvasHeight();
    if (canvasRect.z <= 0 || canvasRect.w <= 0) return {0, 0, 0, 0};
    if (canvasToCameraTable_.size() != size_t(cw) * size_t(ch)) return {0, 0, w, h};
    // The lens map is continuous and one-to-one, so the image of the rectangle lies inside the
    // bounding box of the image of its border (canvas pixels (x, y) = GL window coordinates).
    glm::vec2 lo(1e30f), hi(-1e30f);
    const int x0 = canvasRect.x, y0 = canvasRect.y;
    const int x1 = std::min(cw, canvasRect.x + canvasRect.z) - 1;
    const int y1 = std::min(ch, canvasRect.y + canvasRect.w) - 1;
    auto add = [&](int x, int y) {
        const glm::vec2 q = canvasToCameraTable_[size_t(y) * size_t(cw) + size_t(x)];
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
    };
    for (int x = x0; x <= x1; ++x) add(x, y0), add(x, y1);
    for (int y = y0; y <= y1; ++y) add(x0, y), add(x1, y);
    if (lo.x < -1000.0f || lo.y < -1000.0f) return {0, 0, w, h};  // a ray the camera cannot see
    // + 2 px: the composite reads the canvas at the rounded remap position (0.5 px) and the
    // table is sampled at pixel centres.
    const int cx0 = std::clamp(int(std::floor(lo.x)) - 2, 0, w);
    const int cy0 = std::clamp(int(std::floor(lo.y)) - 2, 0, h);
    const int cx1 = std::clamp(int(std::ceil(hi.x)) + 3, 0, w);
    const int cy1 = std::clamp(int(std::ceil(hi.y)) + 3, 0, h);
    return {cx0, cy0, cx1 - cx0, cy1 - cy0};
}

// Eqs. 6-11 on the camera pixels the diffuse variant left (the mask is 0), each kind of
// rectangle with its variant.
void CompositePass::drawSpecular(FrameContext& ctx, const PassResources& res,
                                 const std::vector<glm::ivec4>& glassRects,
                                 const std::vector<glm::ivec4>& mirrorRects, int withCaustics) {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);  // where the mask is 0
    glDepthMask(GL_FALSE);
    // Filtered pixels (the video term's a = 1) read the L' buffers through the fuzzy units:
    // the newest versions, as the sharp units.
    const bool fuzzy = res.has(kFilteredVideo);
    for (int i = 0; i < 5; ++i)
        glBindTextureUnit(GLuint(kUnitCompositeFuzzyRv + i),
                          (i < 4 ? res.textureOr(kSpecularBuffers[i], ctx.blackTexture())
                                 : res.textureOr(kFilteredVideo, ctx.blackTexture()))
                              .id());
    // With the footage's own grain matched, what mirrors and glass show of the footage is
    // taken without its noise: the grain pass adds the noise of the pixel it is seen at
    // (else the pixel would carry the noise of two places). The noise levels are the
    // earlier frames' (this frame's are measured after the composite); none on the first.
    const NoiseMatchOptions& noise = ctx.options.grain.noise;
    const auto& levels = ctx.grainEstimates.noise();
    const bool denoise = noise.enabled && noise.footageGrain && levels.has_value();
    const SpecularKind glassKind = ctx.options.specular.secondExit ? kGlass : kGlassFirstExitOnly;
    for (const auto& [kind, kindRects] :
         {std::pair{glassKind, &glassRects}, std::pair{kReflectionOnly, &mirrorRects}}) {
        if (kindRects->empty()) continue;
        const SpecularVariant& v = specularVariant(kind);
        v.program.use();
        glUniform1f(v.epsilon, ctx.options.specular.backProjectionEpsilon);
        glUniform1i(v.showVirtual, 1);  // the rectangles are drawn only when showVirtual
        glUniform1i(v.withCaustics, withCaustics);
        glUniform1i(v.secondExit, ctx.options.specular.secondExit ? 1 : 0);
        glUniform1i(v.fuzzyOn, fuzzy ? 1 : 0);
        glUniform1i(v.denoiseFootage, denoise ? 1 : 0);
        if (denoise) glUniform3fv(v.noiseVariance, kNoiseLevels, &levels->variance[0].x);
        ctx.drawFullscreenTriangleIn(*kindRects);  // the pixels the diffuse variant left
    }
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    glDisable(GL_DEPTH_TEST);
}

void CompositePass::execute(FrameContext& ctx, PassResources& res) {
    const bool specular =
        res.has(kSpecularRv) && res.has(kRealSurfaces) && res.has(kReflectionGBuffer);
    // The camera pixels of each specular object's canvas rectangle (the lens map can make two
    // overlap: merged again), apart for the mirrors' rectangles (no glass meets them, nor their
    // camera rectangle a glass one's), which take the reflection-only variant.
    std::vector<glm::ivec4> rects, glassRects, mirrorRects;
    if (specular && ctx.options.composite.showVirtual) {
        for (const glm::ivec4& r : ctx.glassSpecularRects) glassRects.push_back(cameraRect(ctx, r));
        for (const glm::ivec4& r : ctx.mirrorRects) mirrorRects.push_back(cameraRect(ctx, r));
        separateMirrorRects(glassRects, mirrorRects);
        rects = glassRects;
        rects.insert(rects.end(), mirrorRects.begin(), mirrorRects.end());
    }
    if (!rects.empty()) {
        // The mask of the camera pixels that see a specular pixel (inside the rectangles; 1
        // outside): the full variant runs on those only and the diffuse variant on the rest
        // (early depth test; on llvmpipe a pixel costs the whole shader's code).
        maskFbo_.bind();
        maskProgram_.use();
        glViewport(0, 0, ctx.projection.camera.width, ctx.projection.camera.height);
        glBindTextureUnit(kUnitCompositeRemap, remap_.id());
        glBindTextureUnit(kUnitCompositeEmissive, res.texture(kGBufferEmissive).id());
        glDepthMask(GL_TRUE);  // also lets the clear write
        ctx.clearForRects(rects, maskDrawn_, 0, 0, true);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_ALWAYS);
        ctx.drawFullscreenTriangleIn(rects);
        glDepthFunc(GL_LESS);
        glDisable(GL_DEPTH_TEST);
    }
    fbo_.bind();
    glEnable(GL_FRAMEBUFFER_SRGB);
    // The diffuse variant on every pixel the full one (Eqs. 6-11) does not draw. Without a
    // caustic pass the variant that never reads the caustic buffers: reading the black stand-in
    // costs as much as a real buffer on llvmpipe, even behind a uniform branch.
    const int withCaustics = res.has(kCausticRv) ? 1 : 0;
    // The variants with a translucent boundary's reflection read the G-buffer's normal and
    // emissive buffers and the lens table (the frame's translucent pixels: the translucency pass
    // ran; else the emissive buffer's black stand-in marks none).
    const bool translucentReflection =
        translucentReflection_ && res.has(kTranslucentRadiance) && res.has(kGBufferNormal);
    if (withCaustics) {
        ctx.beginFullscreen(programDiffuse_, ctx.projection.camera.width,
                            ctx.projection.camera.height);
        glUniform1i(locShowVirtualDiffuse_, ctx.options.composite.showVirtual ? 1 : 0);
        glUniform1i(locWithCausticsDiffuse_, 1);
    } else {
        ctx.beginFullscreen(programDiffuseNoCaustics_, ctx.projection.camera.width,
                            ctx.projection.camera.height);
        glUniform1i(locShowVirtualNoCaustics_, ctx.options.composite.showVirtual ? 1 : 0);
    }
    glBindTextureUnit(kUnitCompositeCamera, res.texture(kCameraImage).id());
    glBindTextureUnit(kUnitCompositeLRv, res.texture(kLRv).id());
    glBindTextureUnit(kUnitCompositeLR, res.texture(kLR).id());
    glBindTextureUnit(kUnitCompositeCausticRv, res.textureOr(kCausticRv, ctx.blackTexture()).id());
    glBindTextureUnit(kUnitCompositeCausticR, res.textureOr(kCausticR, ctx.blackTexture()).id());
    glBindTextureUnit(kUnitCompositePosition,
                      res.textureOr(kGBufferPosition, ctx.blackTexture()).id());
    glBindTextureUnit(kUnitCompositeRemap, remap_.id());
    glBindTextureUnit(kUnitCompositeNormal, res.textureOr(kGBufferNormal, ctx.blackTexture()).id());
    if (specular || translucentReflection) {
        glBindTextureUnit(kUnitCompositeEmissive, res.texture(kGBufferEmissive).id());
        glBindTextureUnit(kUnitCompositeCanvasToCamera, canvasToCamera_.id());
    }
    if (specular) {
        glBindTextureUnit(kUnitCompositeReflPosition, res.texture(kReflectionGBuffer).id());
        glBindTextureUnit(kUnitCompositeRefrPosition, res.texture(kRefractionGBuffer).id());
        glBindTextureUnit(kUnitCompositeReflWeight, res.texture(kReflectionWeight).id());
        glBindTextureUnit(kUnitCompositeRefrWeight, res.texture(kRefractionWeight).id());
        glBindTextureUnit(kUnitCompositeSpecRv, res.texture(kSpecularRv).id());
        glBindTextureUnit(kUnitCompositeSpecR, res.texture(kSpecularR).id());
        glBindTextureUnit(kUnitCompositeSpecRRefl, res.texture(kSpecularRReflection).id());
        glBindTextureUnit(kUnitCompositeLenv, res.texture(kLenv).id());
        glBindTextureUnit(kUnitCompositeRealSurfaces, res.texture(kRealSurfaces).id());
        glBindTextureUnit(kUnitCompositeCanvasToCamera, canvasToCamera_.id());
        glBindTextureUnit(kUnitCompositeBackPosition,
                          res.textureOr(kBackFacePosition, ctx.blackTexture()).id());
        glBindTextureUnit(kUnitCompositeBackNormal,
                          res.textureOr(kBackFaceNormal, ctx.blackTexture()).id());
        glBindTextureUnit(kUnitCompositeEnvironment,
                          res.textureOr(kEnvironmentMap, ctx.blackTexture()).id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingMaterials,
                         ctx.scene.materialBuffer().id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingSpecularDraws,
                         ctx.scene.specularDrawBuffer().id());
    } else {
        for (int u = kUnitCompositeEmissive; u <= kUnitCompositeCanvasToCamera; ++u)
            if (!translucentReflection ||
                (u != kUnitCompositeEmissive && u != kUnitCompositeCanvasToCamera))
                glBindTextureUnit(GLuint(u), ctx.blackTexture().id());
    }
    if (!rects.empty() && !ctx.options.direct.onSpecularPixels) {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);  // the triangle lies at depth 0.5: where the mask is 1
        glDepthMask(GL_FALSE);
    }
    ctx.drawFullscreenTriangle();
    if (!rects.empty()) drawSpecular(ctx, res, glassRects, mirrorRects, withCaustics);
    if (translucentReflection && ctx.options.composite.showVirtual) {
        // The translucent pixels again, with their boundary's reflection (the variant discards
        // every other pixel, so mirror / glass pixels in the rectangles keep theirs).
        std::vector<glm::ivec4> translucentRects;
        for (const glm::ivec4& r : ctx.translucentRects)
            translucentRects.push_back(cameraRect(ctx, r));
        translucentRects = mergeOverlappingRects(std::move(translucentRects));
        glDisable(GL_DEPTH_TEST);
        programTranslucent_.use();
        glUniform1i(locShowVirtualTranslucent_, 1);
        glUniform1i(locWithCausticsTranslucent_, withCaustics);
        ctx.drawFullscreenTriangleIn(translucentRects);
    }
    glDisable(GL_FRAMEBUFFER_SRGB);
    res.publish(kComposite, linear_);
    res.publish(kCompositeSrgb, srgb_);
    res.publish(kCompositeFootage, footage_);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeCompositePass(const PassInit&) {
    return std::make_unique<CompositePass>();
}

}  // namespace mirage::render
