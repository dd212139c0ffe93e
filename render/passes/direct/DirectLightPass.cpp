#include "render/passes/direct/DirectLightPass.h"

#include "render/FrameGraph.h"

namespace mirage::render {

namespace {
// Scenes without a translucent object never take direct.frag's translucency branch.
std::string translucencyDefines(const GpuScene& scene) {
    return scene.hasTranslucent() ? std::string() : "#define MIRAGE_NO_TRANSLUCENCY 1\n";
}
}  // namespace

DirectLightPass::DirectLightPass(const GpuScene& scene)
    : program_(fullscreenProgram("direct", "passes/direct/direct.frag",
                                 scene.lightingDefines() + translucencyDefines(scene))),
      programNoGlass_(
          fullscreenProgram("direct (no glass shadows)", "passes/direct/direct.frag",
                            scene.lightingDefines(false) + translucencyDefines(scene))) {}

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
    b.write(Resource::DirectRv, GL_RGBA16F, SizeRule::Canvas);
    b.write(Resource::DirectR, GL_RGBA16F, SizeRule::Canvas);
}

PassDecision DirectLightPass::decide(const FrameContext& ctx) const {
    return {true, std::to_string(ctx.scene.lights().size()) + " light(s)" +
                      (ctx.scene.hasEnvironment() || ctx.environment.live ? " + environment" : "")};
}

void DirectLightPass::resize(const FrameContext& ctx) {
    if (rv_.width() == ctx.canvasWidth() && rv_.height() == ctx.canvasHeight()) return;
    rv_ = gl::Texture::create2D("direct L_rv", ctx.canvasWidth(), ctx.canvasHeight(), GL_RGBA16F);
    r_ = gl::Texture::create2D("direct L_r", ctx.canvasWidth(), ctx.canvasHeight(), GL_RGBA16F);
    fbo_ = gl::Framebuffer("direct fbo");
    fbo_.attachColor(0, rv_);
    fbo_.attachColor(1, r_);
    fbo_.finalize(2);
    attachedMask_ = 0;
}

void DirectLightPass::execute(FrameContext& ctx, PassResources& res) {
    const gl::Texture* mask =
        res.has(Resource::SpecularMask) && !ctx.options.diffuseOnSpecularPixels
            ? &res.texture(Resource::SpecularMask)
            : nullptr;
    if (mask && mask->id() != attachedMask_) {  // reallocated only on a resize
        fbo_.attachDepth(*mask);
        fbo_.finalize(2);
        attachedMask_ = mask->id();
    }
    fbo_.bind();
    // Frames in which no light goes through glass use the variant without the glass lookups:
    // llvmpipe pays for a branch's texture reads even when no pixel takes it.
    gl::Program& program = ctx.plan.glassShadows ? program_ : programNoGlass_;
    ctx.beginFullscreen(program, ctx.canvasWidth(), ctx.canvasHeight());
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
    glUniform1i(program.uniformLocation("translucentOn"), translucent ? 1 : 0);
    // Mirror and glass pixels take their light from the specular passes: not shaded here.
    if (mask)
        ctx.drawFullscreenTriangleOutsideSpecular(0, 2);
    else
        ctx.drawFullscreenTriangle();
    res.publish(Resource::DirectRv, rv_);
    res.publish(Resource::DirectR, r_);
}

}  // namespace mirage::render
