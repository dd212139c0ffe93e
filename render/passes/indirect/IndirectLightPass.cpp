#include "render/passes/indirect/IndirectLightPass.h"

#include <algorithm>

#include "render/FrameGraph.h"

namespace mirage::render {

IndirectLightPass::IndirectLightPass()
    : program_(fullscreenProgram("indirect", "passes/indirect/indirect.frag")) {}

void IndirectLightPass::setup(PassBuilder& b) const {
    b.read(Resource::GBufferPosition);
    b.read(Resource::GBufferNormal);
    b.read(Resource::GBufferAlbedo);
    b.read(Resource::Vpls);
    b.read(Resource::ImperfectShadowMaps);
    b.read(Resource::ImperfectShadowMapsReal);
    b.write(Resource::IndirectRv, GL_RGBA16F, SizeRule::GatherTiles);
    b.write(Resource::IndirectR, GL_RGBA16F, SizeRule::GatherTiles);
}

PassDecision IndirectLightPass::decide(const FrameContext& ctx) const {
    const int k = std::max(1, ctx.options.interleave);
    return {true, "interleaved " + std::to_string(k) + "x" + std::to_string(k) + ": " +
                      std::to_string((ctx.options.vplCount + k * k - 1) / (k * k)) +
                      " VPLs per pixel, at 1/" + std::to_string(ctx.gatherScale()) + " resolution"};
}

void IndirectLightPass::resize(const FrameContext& ctx) {
    // Gather resolution: canvas / indirectScale, rounded up to a multiple of K so that the
    // deinterleaved layout (K x K tiles, tile g holding the pixels of VPL group g) is exact.
    const int s = ctx.gatherScale(), k = std::max(1, ctx.options.interleave);
    const int lowW = (ctx.canvasWidth() + s - 1) / s, lowH = (ctx.canvasHeight() + s - 1) / s;
    const int w = (lowW + k - 1) / k * k, h = (lowH + k - 1) / k * k;
    if (w == rv_.width() && h == rv_.height()) return;
    rv_ = gl::Texture::create2D("indirect L_rv (deinterleaved)", w, h, GL_RGBA16F);
    r_ = gl::Texture::create2D("indirect L_r (deinterleaved)", w, h, GL_RGBA16F);
    rv_.setFilter(GL_NEAREST, GL_NEAREST);
    r_.setFilter(GL_NEAREST, GL_NEAREST);
    fbo_ = gl::Framebuffer("indirect fbo");
    fbo_.attachColor(0, rv_);
    fbo_.attachColor(1, r_);
    fbo_.finalize(2);
}

void IndirectLightPass::execute(FrameContext& ctx, PassResources& res) {
    fbo_.bind();
    ctx.beginFullscreen(program_, rv_.width(), rv_.height());  // each tile sets its viewport
    glUniform1i(program_.uniformLocation("scale"), ctx.gatherScale());
    vplTexels_.attachBuffer(res.buffer(Resource::Vpls), GL_RGBA32F);
    glBindTextureUnit(kUnitIndirectVpls, vplTexels_.id());
    glBindTextureUnit(kUnitIndirectPosition, res.texture(Resource::GBufferPosition).id());
    glBindTextureUnit(kUnitIndirectNormal, res.texture(Resource::GBufferNormal).id());
    glBindTextureUnit(kUnitIndirectAlbedo, res.texture(Resource::GBufferAlbedo).id());
    glBindTextureUnit(kUnitIndirectIsmAll, res.texture(Resource::ImperfectShadowMaps).id());
    glBindTextureUnit(kUnitIndirectIsmReal, res.texture(Resource::ImperfectShadowMapsReal).id());
    ctx.emptyVao.bind();
    // One draw per VPL group into its tile: the group is uniform over the draw, so every pixel
    // walks the same VPL list (uniform loads; on llvmpipe divergent SSBO gathers are far slower).
    const int k = std::max(1, ctx.options.interleave);
    const int tw = rv_.width() / k, th = rv_.height() / k;
    const GLint locGroup = program_.uniformLocation("group");
    const GLint locTile = program_.uniformLocation("tileOrigin");
    for (int gy = 0; gy < k; ++gy)
        for (int gx = 0; gx < k; ++gx) {
            glViewport(gx * tw, gy * th, tw, th);
            glUniform2i(locGroup, gx, gy);
            glUniform2i(locTile, gx * tw, gy * th);
            glDrawArrays(GL_TRIANGLES, 0, 3);
        }
    res.publish(Resource::IndirectRv, rv_);
    res.publish(Resource::IndirectR, r_);
}

}  // namespace mirage::render
