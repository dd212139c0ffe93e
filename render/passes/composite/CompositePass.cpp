#include "render/passes/composite/CompositePass.h"

#include "render/passes/backface/BackFacePass.h"
#include "render/passes/gbuffer/GBufferPass.h"
#include "render/passes/specular/SpecularGBufferPass.h"
#include "render/passes/specular/SpecularLightPass.h"

namespace mirage::render {

CompositePass::CompositePass(const GBufferPass& gbuffer)
    : gbuffer_(gbuffer),
      program_(fullscreenProgram("composite", "passes/composite/composite.frag")),
      programDiffuse_(fullscreenProgram("composite (diffuse only)",
                                        "passes/composite/composite.frag",
                                        "#define MIRAGE_DIFFUSE_ONLY 1")) {
    locEpsilon_ = program_.uniformLocation("depthEpsilon");
}

PassDecision CompositePass::decide(const FrameContext&) const {
    return {true, "always: the output image"};
}

void CompositePass::resize(const FrameContext& ctx) {
    const CameraProjection& p = ctx.projection;
    const int w = p.camera.width, h = p.camera.height;
    // Runs before every frame; the camera (and so the remap tables) is fixed for the renderer's
    // life, so only a size change rebuilds them.
    if (linear_.width() == w && linear_.height() == h && canvasToCamera_.width() == p.canvasWidth &&
        canvasToCamera_.height() == p.canvasHeight)
        return;
    linear_ = gl::Texture::create2D("composite linear", w, h, GL_RGBA32F);
    srgb_ = gl::Texture::create2D("composite srgb", w, h, GL_SRGB8_ALPHA8);
    remap_ = gl::Texture::create2D("lens remap", w, h, GL_RG32F);
    remap_.setFilter(GL_NEAREST, GL_NEAREST);
    remap_.upload(GL_RG, GL_FLOAT, p.remap.data());
    {
        const int cw = p.canvasWidth, ch = p.canvasHeight;
        std::vector<glm::vec2> table(size_t(cw) * size_t(ch), glm::vec2(-1e4f));
        for (int y = 0; y < ch; ++y)
            for (int x = 0; x < cw; ++x) {
                const glm::dvec3 ray((x - p.canvasCx) / p.camera.fx, (y - p.canvasCy) / p.camera.fy,
                                     1.0);
                if (auto q = p.camera.project(ray)) table[size_t(y) * cw + x] = glm::vec2(*q);
            }
        canvasToCamera_ = gl::Texture::create2D("canvas to camera", cw, ch, GL_RG32F);
        canvasToCamera_.setFilter(GL_LINEAR, GL_LINEAR);
        canvasToCamera_.upload(GL_RG, GL_FLOAT, table.data());
    }
    fbo_ = gl::Framebuffer("composite fbo");
    fbo_.attachColor(0, linear_);
    fbo_.attachColor(1, srgb_);
    fbo_.finalize(2);
}

void CompositePass::execute(FrameContext& ctx) {
    fbo_.bind();
    glEnable(GL_FRAMEBUFFER_SRGB);
    const bool specular = specHits_ && specLight_ && backFaces_ && ctx.has(Resource::SpecularRv) &&
                          ctx.has(Resource::RealSurfaces);
    ctx.beginFullscreen(specular ? program_ : programDiffuse_, ctx.projection.camera.width,
                        ctx.projection.camera.height);
    auto tex = [&](Resource a, Resource b) -> GLuint {
        if (ctx.has(a)) return ctx.texture(a).id();
        if (ctx.has(b)) return ctx.texture(b).id();
        return ctx.blackTexture().id();
    };
    glBindTextureUnit(0, ctx.has(Resource::CameraImage) ? ctx.texture(Resource::CameraImage).id()
                                                        : ctx.blackTexture().id());
    glBindTextureUnit(1, tex(Resource::LRv, Resource::DirectRv));
    glBindTextureUnit(2, tex(Resource::LR, Resource::DirectR));
    glBindTextureUnit(
        3, ctx.has(Resource::GBuffer) ? gbuffer_.position().id() : ctx.blackTexture().id());
    glBindTextureUnit(4, remap_.id());
    if (specular) {
        glUniform1f(locEpsilon_, ctx.options.backProjectionEpsilon);
        glBindTextureUnit(5, gbuffer_.emissive().id());
        glBindTextureUnit(6, specHits_->reflection().position.id());
        glBindTextureUnit(7, specHits_->refraction().position.id());
        glBindTextureUnit(8, specHits_->reflection().weight.id());
        glBindTextureUnit(9, specHits_->refraction().weight.id());
        glBindTextureUnit(10, specLight_->rv().id());
        glBindTextureUnit(11, specLight_->r().id());
        glBindTextureUnit(12, specLight_->rReflection().id());
        glBindTextureUnit(13, specLight_->env().id());
        glBindTextureUnit(14, ctx.texture(Resource::RealSurfaces).id());
        glBindTextureUnit(15, canvasToCamera_.id());
    } else {
        for (GLuint u = 5; u <= 15; ++u) glBindTextureUnit(u, ctx.blackTexture().id());
    }
    ctx.drawFullscreenTriangle();
    glDisable(GL_FRAMEBUFFER_SRGB);
    ctx.publish(Resource::Composite, &linear_);
}

}  // namespace mirage::render
