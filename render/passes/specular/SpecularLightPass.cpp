#include "render/passes/specular/SpecularLightPass.h"

#include "render/FrameGraph.h"

namespace mirage::render {

namespace {
// GBuf_refl then GBuf_refr, at kUnitSpecLightReflFirst + 0..4 and kUnitSpecLightRefrFirst + 0..4.
constexpr Resource kHitBuffers[10] = {Resource::ReflectionGBuffer,  Resource::ReflectionNormal,
                                      Resource::ReflectionAlbedo,   Resource::ReflectionEmissive,
                                      Resource::ReflectionWeight,   Resource::RefractionGBuffer,
                                      Resource::RefractionNormal,   Resource::RefractionAlbedo,
                                      Resource::RefractionEmissive, Resource::RefractionWeight};
static_assert(kUnitSpecLightRefrFirst == kUnitSpecLightReflFirst + 5);
}  // namespace

SpecularLightPass::SpecularLightPass(const GpuScene& scene)
    : program_(fullscreenProgram("specular light", "passes/specular/specular_light.frag",
                                 scene.lightingDefines())) {
    locUseVpls_ = program_.uniformLocation("useVpls");
    locVplStride_ = program_.uniformLocation("vplStride");
}

void SpecularLightPass::setup(PassBuilder& b) const {
    for (Resource r : kHitBuffers) b.read(r);
    b.read(Resource::GBufferPosition);
    b.read(Resource::SpecularMask);  // depth attachment: shade specular pixels only
    b.read(Resource::EnvironmentMap);
    b.read(Resource::EnvironmentLight);
    for (Resource r : {Resource::ShadowMaps, Resource::ShadowMapsReal, Resource::ShadowGlass,
                       Resource::ShadowGlassReal, Resource::Vpls, Resource::ImperfectShadowMaps,
                       Resource::ImperfectShadowMapsReal})
        b.readOptional(r);
    b.write(Resource::SpecularRv, GL_RGBA16F, SizeRule::Canvas);
    b.write(Resource::SpecularR, GL_RGBA16F, SizeRule::Canvas);
    b.write(Resource::SpecularRReflection, GL_RGBA16F, SizeRule::Canvas);
    b.write(Resource::Lenv, GL_RGBA16F, SizeRule::Canvas);
}

PassDecision SpecularLightPass::decide(const FrameContext& ctx) const {
    const bool vpls = ctx.options.specularVpls && ctx.plan.needVpls;
    return {true, std::to_string(ctx.scene.lights().size()) + " light(s)" +
                      (ctx.scene.hasEnvironment() || ctx.environment.live ? " + environment" : "") +
                      (vpls ? " + VPLs" : "") + " at the reflected/refracted hits"};
}

void SpecularLightPass::resize(const FrameContext& ctx) {
    const int w = ctx.canvasWidth(), h = ctx.canvasHeight();
    if (w == width_ && h == height_) return;
    width_ = w;
    height_ = h;
    rv_ = gl::Texture::create2D("L'_rv", w, h, GL_RGBA16F);
    r_ = gl::Texture::create2D("L'_r", w, h, GL_RGBA16F);
    rRefl_ = gl::Texture::create2D("L'_r reflection share", w, h, GL_RGBA16F);
    env_ = gl::Texture::create2D("L_env", w, h, GL_RGBA16F);
    fbo_ = gl::Framebuffer("specular light fbo");
    fbo_.attachColor(0, rv_);
    fbo_.attachColor(1, r_);
    fbo_.attachColor(2, rRefl_);
    fbo_.attachColor(3, env_);
    fbo_.finalize(4);
    attachedMask_ = 0;  // execute() attaches the specular mask
}

void SpecularLightPass::execute(FrameContext& ctx, PassResources& res) {
    const gl::Texture& mask = res.texture(Resource::SpecularMask);
    if (mask.id() != attachedMask_) {  // specgbuf reallocates it only on a resize
        fbo_.attachDepth(mask);
        fbo_.finalize(4);
        attachedMask_ = mask.id();
    }
    fbo_.bind();
    ctx.beginFullscreen(program_, ctx.canvasWidth(), ctx.canvasHeight());
    for (int i = 0; i < 10; ++i)
        glBindTextureUnit(GLuint(kUnitSpecLightReflFirst + i), res.texture(kHitBuffers[i]).id());
    glBindTextureUnit(kUnitSpecLightShadowAll,
                      res.textureOr(Resource::ShadowMaps, ctx.farShadowTexture()).id());
    glBindTextureUnit(kUnitSpecLightShadowReal,
                      res.textureOr(Resource::ShadowMapsReal, ctx.farShadowTexture()).id());
    glBindTextureUnit(kUnitSpecLightGlassAll,
                      res.textureOr(Resource::ShadowGlass, ctx.noGlassTexture()).id());
    glBindTextureUnit(kUnitSpecLightGlassReal,
                      res.textureOr(Resource::ShadowGlassReal, ctx.noGlassTexture()).id());
    const bool vpls = ctx.options.specularVpls && res.has(Resource::Vpls) &&
                      res.has(Resource::ImperfectShadowMaps);
    if (vpls) {
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingVpls, res.buffer(Resource::Vpls).id());
        glBindTextureUnit(kUnitSpecLightIsmAll, res.texture(Resource::ImperfectShadowMaps).id());
        glBindTextureUnit(kUnitSpecLightIsmReal,
                          res.textureOr(Resource::ImperfectShadowMapsReal,
                                        res.texture(Resource::ImperfectShadowMaps))
                              .id());
    } else {
        glBindTextureUnit(kUnitSpecLightIsmAll, 0);
        glBindTextureUnit(kUnitSpecLightIsmReal, 0);
    }
    glBindTextureUnit(kUnitSpecLightPosition, res.texture(Resource::GBufferPosition).id());
    glBindTextureUnit(kUnitEnvironmentMap, res.texture(Resource::EnvironmentMap).id());
    glBindBufferBase(GL_UNIFORM_BUFFER, kBindingEnvironment,
                     res.buffer(Resource::EnvironmentLight).id());
    glUniform1i(locUseVpls_, vpls ? 1 : 0);
    glUniform1i(locVplStride_, ctx.options.specularVplStride);
    // Only specular pixels pass the early depth test against the mask (the triangle lies at
    // depth 0.5); the rest stay 0 (not a specular pixel).
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_FALSE);
    ctx.drawFullscreenTriangleIn(ctx.specularScissor, 4);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    glDisable(GL_DEPTH_TEST);
    res.publish(Resource::SpecularRv, rv_);
    res.publish(Resource::SpecularR, r_);
    res.publish(Resource::SpecularRReflection, rRefl_);
    res.publish(Resource::Lenv, env_);
}

}  // namespace mirage::render
