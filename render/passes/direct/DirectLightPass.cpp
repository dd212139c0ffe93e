#include "render/passes/direct/DirectLightPass.h"

#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/passes/backface/BackFacePass.h"
#include "render/passes/environment/EnvironmentPass.h"
#include "render/passes/gbuffer/GBufferPass.h"
#include "render/passes/gifilter/GiFilterPass.h"
#include "render/passes/shadow/ShadowPass.h"
#include "render/passes/translucency/TranslucencyPass.h"

namespace mirage::render {

namespace {
// Scenes without a translucent object never take direct.frag's translucency branch.
std::string translucencyDefines(const GpuScene& scene) {
    return scene.hasTranslucent() ? std::string() : "#define MIRAGE_NO_TRANSLUCENCY 1\n";
}

// R^T K^-1 on the canvas: the world direction, at camera-frame depth 1, of canvas pixel (x, y)
// with pixel centres at integers (x / z = (x - cx) / fx, as the projection matrix maps it).
glm::mat3 rayFromCanvasPixel(const FrameContext& ctx) {
    const CameraProjection& p = ctx.projection;
    glm::mat3 kInv(1.0f);  // column-major: [column][row]
    kInv[0][0] = float(1.0 / p.camera.fx);
    kInv[1][1] = float(1.0 / p.camera.fy);
    kInv[2][0] = float(-p.canvasCx / p.camera.fx);
    kInv[2][1] = float(-p.canvasCy / p.camera.fy);
    return glm::transpose(glm::mat3(ctx.frame.viewMatrix)) * kInv;
}

}  // namespace

DirectLightPass::DirectLightPass(const GpuScene& scene)
    : sceneDefines_(scene.lightingDefines() + translucencyDefines(scene)),
      sceneDefinesNoGlass_(scene.lightingDefines(false) + translucencyDefines(scene)) {
    program(true, false, false);  // the variant of frames without VPLs, compiled up front
}

gl::Program& DirectLightPass::program(bool glass, bool indirect, bool keepDirect, bool highlight) {
    keepDirect = keepDirect && indirect;  // without indirect light LRv is the direct light
    const auto key = std::make_tuple(glass, indirect, keepDirect, highlight);
    if (auto it = programs_.find(key); it != programs_.end()) return it->second;
    std::string defines = glass ? sceneDefines_ : sceneDefinesNoGlass_;
    if (indirect && !highlight) defines += "#define MIRAGE_WITH_INDIRECT 1\n";
    if (keepDirect) defines += "#define MIRAGE_KEEP_DIRECT 1\n";
    if (highlight) defines += "#define MIRAGE_ROUGH_HIGHLIGHT 1\n";
    gl::Program p = fullscreenProgram(
        std::string("direct") + (highlight ? " rough highlight" : "") +
            (glass ? "" : " (no glass shadows)") + (indirect && !highlight ? " + indirect" : "") +
            (keepDirect ? " (direct kept)" : ""),
        "passes/direct/direct.frag", defines);
    return programs_.emplace(key, std::move(p)).first->second;
}

// The punctual lights' glossy highlight on the rough mirror / metal / glass pixels (direct.frag's
// MIRAGE_ROUGH_HIGHLIGHT variant) inside the specular rectangles: where the mask is attached
// only its specular pixels (depth 0 < the triangle's 0.5), else every pixel the variant keeps.
void DirectLightPass::drawRoughHighlight(FrameContext& ctx, gl::Program& prog, bool masked) {
    prog.use();
    glUniform1i(prog.uniformLocation("translucentOn"), 0);
    if (masked) {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_GREATER);
        glDepthMask(GL_FALSE);
    }
    glEnable(GL_SCISSOR_TEST);
    for (const glm::ivec4& r : ctx.specularRects) {
        if (r.z <= 0 || r.w <= 0) continue;
        glScissor(r.x, r.y, r.z, r.w);
        ctx.drawFullscreenTriangle();
    }
    glDisable(GL_SCISSOR_TEST);
    if (masked) {
        glDepthMask(GL_TRUE);
        glDepthFunc(GL_LESS);
        glDisable(GL_DEPTH_TEST);
    }
}

void DirectLightPass::setup(PassBuilder& b) const {
    b.read(kGBufferPosition);
    b.read(kGBufferNormal);
    b.read(kGBufferAlbedo);
    b.read(kGBufferEmissive);
    b.read(kEnvironmentLight);
    b.readOptional(kShadowMaps);  // none: no light has a caster (unshadowed)
    b.readOptional(kShadowMapsReal);
    b.readOptional(kShadowGlass);  // none: no glass in a light's cone
    b.readOptional(kShadowGlassReal);
    b.readOptional(kTranslucentGrid);  // none: no translucent object (or its pass off)
    b.readOptional(kTranslucentRadiance);
    b.readOptional(kTranslucentLut);
    b.readOptional(kSpecularMask);  // none: no mirror or glass object in view
    b.readOptional(kGatherLight);   // none: no VPL light this frame
    // none: no mirror or glass object in view (rough glass's transmitted light needs them)
    b.readOptional(kBackFacePosition);
    b.readOptional(kBackFaceNormal);
    b.create(kLRv, {GL_RGBA16F, SizeRule::Canvas, Storage::PassOwned});
    b.create(kLR, {GL_RGBA16F, SizeRule::Canvas, Storage::PassOwned});
    // The direct light alone: LRv / LR themselves in frames without VPL light, else written
    // apart only with RendererOptions::direct.keepDirectLight.
    b.create(kDirectRv, {GL_RGBA16F, SizeRule::Canvas, Storage::PassOwned});
    b.create(kDirectR, {GL_RGBA16F, SizeRule::Canvas, Storage::PassOwned});
}

PassDecision DirectLightPass::decide(const FrameContext& ctx) const {
    const int rough = ctx.scene.roughReflectorCount() + ctx.scene.roughGlassCount();
    return {true,
            std::to_string(ctx.scene.lights().size()) + " light(s)" +
                (ctx.scene.hasEnvironment() || ctx.environment.live ? " + environment" : "") +
                (ctx.plan.needVpls ? " + the upsampled indirect light" : "") +
                (rough > 0 && ctx.options.direct.roughHighlight
                     ? " + the lights' highlight on " + std::to_string(rough) +
                           " rough mirror / metal / glass object(s)"
                     : "") +
                (ctx.scene.roughGlassCount() > 0 && ctx.options.direct.roughHighlight &&
                         ctx.options.direct.roughTransmission
                     ? " + the lights through " + std::to_string(ctx.scene.roughGlassCount()) +
                           " rough glass object(s)"
                     : "")};
}

void DirectLightPass::resize(const FrameContext& ctx) {
    if (rv_.width() == ctx.canvasWidth() && rv_.height() == ctx.canvasHeight()) return;
    const int w = ctx.canvasWidth(), h = ctx.canvasHeight();
    rv_ = gl::Texture::create2D("L_rv", w, h, GL_RGBA16F);
    r_ = gl::Texture::create2D("L_r", w, h, GL_RGBA16F);
    fbo_ = gl::Framebuffer("direct fbo");
    fbo_.attachColor(0, rv_);
    fbo_.attachColor(1, r_);
    fbo_.finalize(2);
    attachedMask_ = 0;
    if (!ctx.options.direct.keepDirectLight) return;
    directRv_ = gl::Texture::create2D("direct L_rv", w, h, GL_RGBA16F);
    directR_ = gl::Texture::create2D("direct L_r", w, h, GL_RGBA16F);
    keepFbo_ = gl::Framebuffer("direct fbo (direct light kept)");
    keepFbo_.attachColor(0, rv_);
    keepFbo_.attachColor(1, r_);
    keepFbo_.attachColor(2, directRv_);
    keepFbo_.attachColor(3, directR_);
    keepFbo_.finalize(4);
    keepAttachedMask_ = 0;
}

void DirectLightPass::execute(FrameContext& ctx, PassResources& res) {
    const bool indirect = res.has(kGatherLight);
    const bool keep = indirect && ctx.options.direct.keepDirectLight;
    gl::Framebuffer& fbo = keep ? keepFbo_ : fbo_;
    const int targets = keep ? 4 : 2;
    GLuint& attached = keep ? keepAttachedMask_ : attachedMask_;
    const gl::Texture* mask = res.has(kSpecularMask) && !ctx.options.direct.onSpecularPixels
                                  ? &res.texture(kSpecularMask)
                                  : nullptr;
    if (mask && mask->id() != attached) {  // reallocated only on a resize
        fbo.attachDepth(*mask);
        fbo.finalize(targets);
        attached = mask->id();
    }
    // Frames in which no light goes through glass use the variant without the glass lookups:
    // llvmpipe pays for a branch's texture reads even when no pixel takes it.
    gl::Program& prog = program(ctx.plan.glassShadows, indirect, keep);
    fbo.bind();
    ctx.beginFullscreen(prog, ctx.canvasWidth(), ctx.canvasHeight());
    glBindTextureUnit(kUnitDirectPosition, res.texture(kGBufferPosition).id());
    glBindTextureUnit(kUnitDirectNormal, res.texture(kGBufferNormal).id());
    glBindTextureUnit(kUnitDirectAlbedo, res.texture(kGBufferAlbedo).id());
    glBindTextureUnit(kUnitDirectEmissive, res.texture(kGBufferEmissive).id());
    glBindTextureUnit(kUnitDirectShadowAll,
                      res.textureOr(kShadowMaps, ctx.farShadowTexture()).id());
    glBindTextureUnit(kUnitDirectShadowReal,
                      res.textureOr(kShadowMapsReal, ctx.farShadowTexture()).id());
    glBindTextureUnit(kUnitDirectGlassAll, res.textureOr(kShadowGlass, ctx.noGlassTexture()).id());
    glBindTextureUnit(kUnitDirectGlassReal,
                      res.textureOr(kShadowGlassReal, ctx.noGlassTexture()).id());
    glBindBufferBase(GL_UNIFORM_BUFFER, kBindingEnvironment, res.buffer(kEnvironmentLight).id());
    const bool translucent =
        res.has(kTranslucentGrid) && res.has(kTranslucentRadiance) && res.has(kTranslucentLut);
    if (translucent) {
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingTranslucentGrid,
                         res.buffer(kTranslucentGrid).id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingTranslucentRadiance,
                         res.buffer(kTranslucentRadiance).id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingTranslucentLut,
                         res.buffer(kTranslucentLut).id());
    }
    glUniform1i(prog.uniformLocation("translucentOn"), translucent ? 1 : 0);
    glUniform1i(prog.uniformLocation("translucentSeeThrough"),
                translucent && ctx.options.translucency.seeThrough ? 1 : 0);
    if (indirect) {
        glBindTextureUnit(kUnitDirectGatherLight, res.texture(kGatherLight).id());
        glUniform1i(prog.uniformLocation("gatherScale"), ctx.gatherScale());
        glUniformMatrix3fv(prog.uniformLocation("rayFromPixel"), 1, GL_FALSE,
                           &rayFromCanvasPixel(ctx)[0][0]);
    }
    // Mirror and glass pixels take their light from the specular passes: not shaded here.
    if (mask)
        ctx.drawFullscreenTriangleOutsideSpecular(0, targets);
    else
        ctx.drawFullscreenTriangle();
    const bool roughInView =
        ctx.scene.roughReflectorCount() + ctx.scene.roughGlassCount() > 0 && res.has(kSpecularMask);
    if (roughInView && ctx.options.direct.roughHighlight) {
        gl::Program& highlight = program(ctx.plan.glassShadows, indirect, keep, true);
        highlight.use();
        // Rough glass's transmitted light follows the sharp path through the back faces.
        const bool transmission = ctx.options.direct.roughTransmission &&
                                  ctx.scene.roughGlassCount() > 0 && res.has(kBackFacePosition);
        glUniform1i(highlight.uniformLocation("roughTransmissionOn"), transmission ? 1 : 0);
        if (transmission) {
            glBindTextureUnit(kUnitDirectBackPosition, res.texture(kBackFacePosition).id());
            glBindTextureUnit(kUnitDirectBackNormal, res.texture(kBackFaceNormal).id());
            glUniform1i(highlight.uniformLocation("roughRefractionSteps"),
                        ctx.options.specular.refractionMarchSteps);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingMaterials,
                             ctx.scene.materialBuffer().id());
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingSpecularDraws,
                             ctx.scene.specularDrawBuffer().id());
        }
        drawRoughHighlight(ctx, highlight, mask != nullptr);
    }
    res.publish(kLRv, rv_);
    res.publish(kLR, r_);
    if (!indirect) {  // the GI solutions are the direct light
        res.publish(kDirectRv, rv_);
        res.publish(kDirectR, r_);
    } else if (keep) {
        res.publish(kDirectRv, directRv_);
        res.publish(kDirectR, directR_);
    }
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeDirectLightPass(const PassInit& init) {
    return std::make_unique<DirectLightPass>(init.gpuScene);
}

}  // namespace mirage::render
