#include "render/passes/specular/SpecularGBufferPass.h"

#include <array>

#include "render/FrameGraph.h"
#include "render/passes/impostor/ImpostorPass.h"

namespace mirage::render {
namespace {

void allocate(SpecularHitBuffer& b, const std::string& what, int w, int h,
              const gl::Texture& mask) {
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
    b.fbo.attachDepth(mask);
    b.fbo.finalize(5);
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
    b.write(position, GL_RGBA32F, SizeRule::Canvas);
    for (Resource r : {normal, albedo, emissive, weight}) b.write(r, GL_RGBA16F, SizeRule::Canvas);
}

}  // namespace

SpecularGBufferPass::SpecularGBufferPass()
    : programs_{fullscreenProgram("specular gbuffer (reflection)",
                                  "passes/specular/specular_gbuffer.frag",
                                  "#define MIRAGE_SPECULAR_MODE 0"),
                fullscreenProgram("specular gbuffer (refraction)",
                                  "passes/specular/specular_gbuffer.frag",
                                  "#define MIRAGE_SPECULAR_MODE 1")},
      maskProgram_(fullscreenProgram("specular pixel mask", "passes/specular/specular_mask.frag")) {
}

void SpecularGBufferPass::setup(PassBuilder& b) const {
    for (Resource r :
         {Resource::GBufferPosition, Resource::GBufferNormal, Resource::GBufferEmissive,
          Resource::BackFacePosition, Resource::BackFaceNormal})
        b.read(r);
    ImpostorPass::declareTracing(b);
    declare(b, Resource::ReflectionGBuffer, Resource::ReflectionNormal, Resource::ReflectionAlbedo,
            Resource::ReflectionEmissive, Resource::ReflectionWeight);
    b.write(Resource::SpecularMask, GL_DEPTH_COMPONENT32F, SizeRule::Canvas);
    declare(b, Resource::RefractionGBuffer, Resource::RefractionNormal, Resource::RefractionAlbedo,
            Resource::RefractionEmissive, Resource::RefractionWeight);
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
    mask_ = gl::Texture::create2D("specular pixel mask", w, h, GL_DEPTH_COMPONENT32F);
    maskFbo_ = gl::Framebuffer("specular pixel mask fbo");
    maskFbo_.attachDepth(mask_);
    maskFbo_.finalize(0);
    maskDrawn_.markAll();
    allocate(refl_, "GBuf_refl", w, h, mask_);
    allocate(refr_, "GBuf_refr", w, h, mask_);
}

void SpecularGBufferPass::execute(FrameContext& ctx, PassResources& res) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingMaterials, ctx.scene.materialBuffer().id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingSpecularDraws,
                     ctx.scene.specularDrawBuffer().id());
    glBindTextureUnit(kUnitSpecGbufPosition, res.texture(Resource::GBufferPosition).id());
    glBindTextureUnit(kUnitSpecGbufNormal, res.texture(Resource::GBufferNormal).id());
    glBindTextureUnit(kUnitSpecGbufEmissive, res.texture(Resource::GBufferEmissive).id());
    glBindTextureUnit(kUnitSpecGbufBackPosition, res.texture(Resource::BackFacePosition).id());
    glBindTextureUnit(kUnitSpecGbufBackNormal, res.texture(Resource::BackFaceNormal).id());
    ImpostorPass::bindForTracing(res, impostorTables_);  // kUnitImpostor*, the header block
    // The specular-pixel depth mask: outside the rectangles it stays cleared (1, not specular).
    maskFbo_.bind();
    ctx.beginFullscreen(maskProgram_, ctx.canvasWidth(), ctx.canvasHeight());
    glDepthMask(GL_TRUE);  // also lets the clear write
    ctx.clearForRects(ctx.specularRects, maskDrawn_, 0, 0, true);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_ALWAYS);
    ctx.drawFullscreenTriangleIn(ctx.specularRects);
    for (int mode = 0; mode < 2; ++mode) {
        SpecularHitBuffer& hits = mode == 0 ? refl_ : refr_;
        hits.fbo.bind();
        const gl::Program& program = programs_[mode];
        ctx.beginFullscreen(program, ctx.canvasWidth(), ctx.canvasHeight());
        if (mode == 1)
            glUniform1i(program.uniformLocation("marchSteps"), ctx.options.refractionMarchSteps);
        // Only specular pixels pass the early depth test (the triangle lies at depth 0.5).
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_GREATER);
        glDepthMask(GL_FALSE);
        // 0 elsewhere: no specular pixel, or (refraction) none that refracts.
        const std::vector<glm::ivec4>& rects = mode == 0 ? ctx.specularRects : ctx.refractiveRects;
        ctx.clearForRects(rects, hits.drawn, 0, 5);
        ctx.drawFullscreenTriangleIn(rects);
    }
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    glDisable(GL_DEPTH_TEST);
    publish(res, refl_, Resource::ReflectionGBuffer, Resource::ReflectionNormal,
            Resource::ReflectionAlbedo, Resource::ReflectionEmissive, Resource::ReflectionWeight);
    res.publish(Resource::SpecularMask, mask_);
    publish(res, refr_, Resource::RefractionGBuffer, Resource::RefractionNormal,
            Resource::RefractionAlbedo, Resource::RefractionEmissive, Resource::RefractionWeight);
}

}  // namespace mirage::render
