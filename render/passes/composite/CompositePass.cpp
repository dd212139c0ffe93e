#include "render/passes/composite/CompositePass.h"

#include "render/Shaders.h"
#include "render/passes/gbuffer/GBufferPass.h"

namespace mirage::render {

CompositePass::CompositePass(const GBufferPass& gbuffer)
    : gbuffer_(gbuffer),
      program_("composite",
               {{GL_VERTEX_SHADER, "fullscreen.vert", shaders::source("fullscreen.vert")},
                {GL_FRAGMENT_SHADER, "passes/composite/composite.frag",
                 shaders::source("passes/composite/composite.frag")}}) {}

PassDecision CompositePass::decide(const FrameContext&) const {
    return {true, "always: the output image"};
}

void CompositePass::resize(const FrameContext& ctx) {
    const CameraProjection& p = ctx.projection;
    const int w = p.camera.width, h = p.camera.height;
    linear_ = gl::Texture::create2D("composite linear", w, h, GL_RGBA32F);
    srgb_ = gl::Texture::create2D("composite srgb", w, h, GL_SRGB8_ALPHA8);
    remap_ = gl::Texture::create2D("lens remap", w, h, GL_RG32F);
    remap_.setFilter(GL_NEAREST, GL_NEAREST);
    remap_.upload(GL_RG, GL_FLOAT, p.remap.data());
    fbo_ = gl::Framebuffer("composite fbo");
    fbo_.attachColor(0, linear_);
    fbo_.attachColor(1, srgb_);
    fbo_.finalize(2);
}

void CompositePass::execute(FrameContext& ctx) {
    fbo_.bind();
    glViewport(0, 0, ctx.projection.camera.width, ctx.projection.camera.height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glEnable(GL_FRAMEBUFFER_SRGB);
    program_.use();
    ctx.bindFrameBlocks();
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
    ctx.emptyVao.bind();
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDisable(GL_FRAMEBUFFER_SRGB);
    ctx.publish(Resource::Composite, &linear_);
}

}  // namespace mirage::render
