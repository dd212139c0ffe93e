#include "render/passes/direct/DirectLightPass.h"

#include "render/FrameGraph.h"

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

gl::Program& DirectLightPass::program(bool glass, bool indirect, bool keepDirect) {
    keepDirect = keepDirect && indirect;  // without indirect light LRv is the direct light
    const auto key = std::make_tuple(glass, indirect, keepDirect);
    if (auto it = programs_.find(key); it != programs_.end()) return it->second;
    std::string defines = glass ? sceneDefines_ : sceneDefinesNoGlass_;
    if (indirect) defines += "#define MIRAGE_WITH_INDIRECT 1\n";
    if (keepDirect) defines += "#define MIRAGE_KEEP_DIRECT 1\n";
    gl::Program p = fullscreenProgram(std::string("direct") + (glass ? "" : " (no glass shadows)") +
                                          (indirect ? " + indirect" : "") +
                                          (keepDirect ? " (direct kept)" : ""),
                                      "passes/direct/direct.frag", defines);
    return programs_.emplace(key, std::move(p)).first->second;
}

void DirectLightPass::setup(PassBuilder& b) const {
    b.read(Resource::GBufferPosition);
    b.read(Resource::GBufferNormal);
    b.read(Resource::GBufferAlbedo);
    b.read(Resource::GBufferEmissive);
    b.read(Resource::EnvironmentLight);
    b.readOptional(Resource::ShadowMaps);  // none: no light has a caster (unshadowed)
    b.readOptional(Resource::ShadowMapsReal);
    b.readOptional(Resource::ShadowGlass);  // none: no glass in a light's cone
    b.readOptional(Resource::ShadowGlassReal);
    b.readOptional(Resource::TranslucentGrid);  // none: no translucent object (or its pass off)
    b.readOptional(Resource::TranslucentRadiance);
    b.readOptional(Resource::SpecularMask);  // none: no mirror or glass object in view
    b.readOptional(Resource::GatherLight);   // none: no VPL light this frame
    b.write(Resource::LRv, GL_RGBA16F, SizeRule::Canvas);
    b.write(Resource::LR, GL_RGBA16F, SizeRule::Canvas);
    // The direct light alone: LRv / LR themselves in frames without VPL light, else written
    // apart only with RendererOptions::keepDirectLight.
    b.write(Resource::DirectRv, GL_RGBA16F, SizeRule::Canvas);
    b.write(Resource::DirectR, GL_RGBA16F, SizeRule::Canvas);
}

PassDecision DirectLightPass::decide(const FrameContext& ctx) const {
    return {true, std::to_string(ctx.scene.lights().size()) + " light(s)" +
                      (ctx.scene.hasEnvironment() || ctx.environment.live ? " + environment" : "") +
                      (ctx.plan.needVpls ? " + the upsampled indirect light" : "")};
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
    if (!ctx.options.keepDirectLight) return;
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
    const bool indirect = res.has(Resource::GatherLight);
    const bool keep = indirect && ctx.options.keepDirectLight;
    gl::Framebuffer& fbo = keep ? keepFbo_ : fbo_;
    const int targets = keep ? 4 : 2;
    GLuint& attached = keep ? keepAttachedMask_ : attachedMask_;
    const gl::Texture* mask =
        res.has(Resource::SpecularMask) && !ctx.options.diffuseOnSpecularPixels
            ? &res.texture(Resource::SpecularMask)
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
    glBindTextureUnit(kUnitDirectPosition, res.texture(Resource::GBufferPosition).id());
    glBindTextureUnit(kUnitDirectNormal, res.texture(Resource::GBufferNormal).id());
    glBindTextureUnit(kUnitDirectAlbedo, res.texture(Resource::GBufferAlbedo).id());
    glBindTextureUnit(kUnitDirectEmissive, res.texture(Resource::GBufferEmissive).id());
    glBindTextureUnit(kUnitDirectShadowAll,
                      res.textureOr(Resource::ShadowMaps, ctx.farShadowTexture()).id());
    glBindTextureUnit(kUnitDirectShadowReal,
                      res.textureOr(Resource::ShadowMapsReal, ctx.farShadowTexture()).id());
    glBindTextureUnit(kUnitDirectGlassAll,
                      res.textureOr(Resource::ShadowGlass, ctx.noGlassTexture()).id());
    glBindTextureUnit(kUnitDirectGlassReal,
                      res.textureOr(Resource::ShadowGlassReal, ctx.noGlassTexture()).id());
    glBindBufferBase(GL_UNIFORM_BUFFER, kBindingEnvironment,
                     res.buffer(Resource::EnvironmentLight).id());
    const bool translucent =
        res.has(Resource::TranslucentGrid) && res.has(Resource::TranslucentRadiance);
    if (translucent) {
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingTranslucentGrid,
                         res.buffer(Resource::TranslucentGrid).id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingTranslucentRadiance,
                         res.buffer(Resource::TranslucentRadiance).id());
    }
    glUniform1i(prog.uniformLocation("translucentOn"), translucent ? 1 : 0);
    if (indirect) {
        glBindTextureUnit(kUnitDirectGatherLight, res.texture(Resource::GatherLight).id());
        glUniform1i(prog.uniformLocation("gatherScale"), ctx.gatherScale());
        glUniformMatrix3fv(prog.uniformLocation("rayFromPixel"), 1, GL_FALSE,
                           &rayFromCanvasPixel(ctx)[0][0]);
    }
    // Mirror and glass pixels take their light from the specular passes: not shaded here.
    if (mask)
        ctx.drawFullscreenTriangleOutsideSpecular(0, targets);
    else
        ctx.drawFullscreenTriangle();
    res.publish(Resource::LRv, rv_);
    res.publish(Resource::LR, r_);
    if (!indirect) {  // the GI solutions are the direct light
        res.publish(Resource::DirectRv, rv_);
        res.publish(Resource::DirectR, r_);
    } else if (keep) {
        res.publish(Resource::DirectRv, directRv_);
        res.publish(Resource::DirectR, directR_);
    }
}

}  // namespace mirage::render
