#include "render/passes/indirect/IndirectLightPass.h"

#include <algorithm>

#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/passes/gbuffer/GBufferPass.h"
#include "render/passes/ism/IsmPass.h"
#include "render/passes/vpl/VplPass.h"

namespace mirage::render {

IndirectLightPass::IndirectLightPass()
    : program_(fullscreenProgram("indirect", "passes/indirect/indirect.frag")) {}

void IndirectLightPass::setup(PassBuilder& b) const {
    b.read(kGBufferPosition);
    b.read(kGBufferNormal);
    b.read(kGBufferAlbedo);
    b.read(kVpls);
    b.read(kImperfectShadowMaps);
    b.read(kImperfectShadowMapsReal);
    // Transient: the graph allocates them (every texel is written each frame: one draw per tile).
    b.create(kIndirectRv, {GL_RGBA16F, SizeRule::GatherTiles});
    b.create(kIndirectR, {GL_RGBA16F, SizeRule::GatherTiles});
}

PassDecision IndirectLightPass::decide(const FrameContext& ctx) const {
    const int k = std::max(1, ctx.options.indirect.interleave);
    return {true, "interleaved " + std::to_string(k) + "x" + std::to_string(k) + ": " +
                      std::to_string((ctx.options.vpl.count + k * k - 1) / (k * k)) +
                      " VPLs per pixel, at 1/" + std::to_string(ctx.gatherScale()) + " resolution"};
}

void IndirectLightPass::resize(const FrameContext&) {}  // its targets are the graph's

void IndirectLightPass::execute(FrameContext& ctx, PassResources& res) {
    // Gather resolution: canvas / indirectScale, rounded up to a multiple of K so that the
    // deinterleaved layout (K x K tiles, tile g holding the pixels of VPL group g) is exact
    // (SizeRule::GatherTiles).
    const gl::Texture& rv = res.target(kIndirectRv);
    const gl::Texture& r = res.target(kIndirectR);
    fbo_.bind({&rv, &r});
    ctx.beginFullscreen(program_, rv.width(), rv.height());  // each tile sets its viewport
    glUniform1i(program_.uniformLocation("scale"), ctx.gatherScale());
    vplTexels_.attachBuffer(res.buffer(kVpls), GL_RGBA32F);
    glBindTextureUnit(kUnitIndirectVpls, vplTexels_.id());
    glBindTextureUnit(kUnitIndirectPosition, res.texture(kGBufferPosition).id());
    glBindTextureUnit(kUnitIndirectNormal, res.texture(kGBufferNormal).id());
    glBindTextureUnit(kUnitIndirectAlbedo, res.texture(kGBufferAlbedo).id());
    glBindTextureUnit(kUnitIndirectIsmAll, res.texture(kImperfectShadowMaps).id());
    glBindTextureUnit(kUnitIndirectIsmReal, res.texture(kImperfectShadowMapsReal).id());
    ctx.emptyVao.bind();
    // One draw per VPL group into its tile: the group is uniform over the draw, so every pixel
    // walks the same VPL list (uniform loads; on llvmpipe divergent SSBO gathers are far slower).
    const int k = std::max(1, ctx.options.indirect.interleave);
    const int tw = rv.width() / k, th = rv.height() / k;
    const GLint locGroup = program_.uniformLocation("group");
    const GLint locTile = program_.uniformLocation("tileOrigin");
    for (int gy = 0; gy < k; ++gy)
        for (int gx = 0; gx < k; ++gx) {
            glViewport(gx * tw, gy * th, tw, th);
            glUniform2i(locGroup, gx, gy);
            glUniform2i(locTile, gx * tw, gy * th);
            glDrawArrays(GL_TRIANGLES, 0, 3);
        }
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeIndirectLightPass(const PassInit&) {
    return std::make_unique<IndirectLightPass>();
}

}  // namespace mirage::render
