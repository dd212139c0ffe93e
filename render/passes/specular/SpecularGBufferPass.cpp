#include "render/passes/specular/SpecularGBufferPass.h"

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
    b.fbo.finalize(5);
}

}  // namespace

SpecularGBufferPass::SpecularGBufferPass(const GBufferPass& gbuffer, const BackFacePass& backFaces,
                                         const ImpostorPass& impostors)
    : gbuffer_(gbuffer),
      backFaces_(backFaces),
      impostors_(impostors),
      program_(fullscreenProgram("specular gbuffer", "passes/specular/specular_gbuffer.frag")) {
    locMode_ = program_.uniformLocation("mode");
    locSteps_ = program_.uniformLocation("marchSteps");
}

PassDecision SpecularGBufferPass::decide(const FrameContext& ctx) const {
    if (!ctx.has(Resource::BackFaces)) return {false, "no mirror or glass object in the scene"};
    if (!ctx.has(Resource::Impostors)) return {false, "no impostors of the surroundings"};
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
}

void SpecularGBufferPass::execute(FrameContext& ctx) {
    ctx.beginFullscreen(program_, ctx.canvasWidth(), ctx.canvasHeight());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingMaterials, ctx.scene.materialBuffer().id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingSpecularDraws,
                     ctx.scene.specularDrawBuffer().id());
    glBindTextureUnit(0, gbuffer_.position().id());
    glBindTextureUnit(1, gbuffer_.normal().id());
    glBindTextureUnit(2, gbuffer_.emissive().id());
    glBindTextureUnit(3, backFaces_.position().id());
    glBindTextureUnit(4, backFaces_.normal().id());
    glUniform1i(locSteps_, ctx.options.refractionMarchSteps);
    impostors_.bindForTracing();  // texture units 16..23, storage bindings 6..7
    ctx.emptyVao.bind();
    for (int mode = 0; mode < 2; ++mode) {
        (mode == 0 ? refl_ : refr_).fbo.bind();
        glUniform1i(locMode_, mode);
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    ctx.publish(Resource::ReflectionGBuffer, &refl_.position);
    ctx.publish(Resource::RefractionGBuffer, &refr_.position);
}

}  // namespace mirage::render
