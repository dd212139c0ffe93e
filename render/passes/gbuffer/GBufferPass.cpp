#include "render/passes/gbuffer/GBufferPass.h"

#include <string>

#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
namespace mirage::render {

GBufferPass::GBufferPass(MaterialMaps maps)
    : program_(rasterProgram(
          "gbuffer", "passes/gbuffer/gbuffer.vert", "passes/gbuffer/gbuffer.frag",
          std::string("#define MIRAGE_GBUFFER_MATERIAL 1\n") +
              (maps.baseColor ? "#define MIRAGE_BASE_COLOR_MAPS 1\n" : "") +
              (maps.metallicRoughness ? "#define MIRAGE_METALLIC_ROUGHNESS_MAPS 1\n" : ""))),
      maskProgram_(fullscreenProgram("specular pixel mask", "passes/gbuffer/specular_mask.frag")) {
    locSpecularSlot_ = program_.uniformLocation("specularSlot");
}

void GBufferPass::setup(PassBuilder& b) const {
    b.create(kGBufferPosition, {GL_RGBA32F, SizeRule::Canvas, Storage::PassOwned});
    b.create(kGBufferNormal, {GL_RGBA16F, SizeRule::Canvas, Storage::PassOwned});
    b.create(kGBufferAlbedo, {GL_RGBA16F, SizeRule::Canvas, Storage::PassOwned});
    b.create(kGBufferEmissive, {GL_RGBA16F, SizeRule::Canvas, Storage::PassOwned});
    b.create(kRealSurfaces, {GL_RGBA32F, SizeRule::Canvas, Storage::PassOwned});
    b.create(kSpecularMask, {GL_DEPTH_COMPONENT32F, SizeRule::Canvas, Storage::PassOwned});
}

bool GBufferPass::specularInView(const FrameContext& ctx) {
    // As the back-face pass decides, behind which every specular pass runs.
    const glm::ivec4& r = ctx.specularScissor;
    return !ctx.scene.specularDraws().empty() && r.z > 0 && r.w > 0;
}

bool GBufferPass::separateRealSurfaces(const FrameContext& ctx) {
    // Its readers (the specular passes, the composite's specular variant) run only behind the
    // back-face pass, which runs only with a mirror or glass object in view.
    if (!specularInView(ctx)) return false;
    for (const DrawItem& d : ctx.scene.draws())
        if (d.origin == Origin::Virtual) return true;
    return false;
}

PassDecision GBufferPass::decide(const FrameContext& ctx) const {
    if (ctx.scene.draws().empty()) return {false, "the scene has no geometry"};
    return {true,
            std::to_string(ctx.scene.draws().size()) + " draws" +
                (separateRealSurfaces(ctx) ? ", real first (nearest real surfaces kept)" : "") +
                (specularInView(ctx) ? ", specular pixel mask" : "")};
}

void GBufferPass::resize(const FrameContext& ctx) {
    const int w = ctx.canvasWidth(), h = ctx.canvasHeight();
    if (position_.width() == w && position_.height() == h) return;  // runs before every frame
    position_ = gl::Texture::create2D("gbuffer position", w, h, GL_RGBA32F);
    normal_ = gl::Texture::create2D("gbuffer normal", w, h, GL_RGBA16F);
    albedo_ = gl::Texture::create2D("gbuffer albedo", w, h, GL_RGBA16F);
    emissive_ = gl::Texture::create2D("gbuffer emissive", w, h, GL_RGBA16F);
    depth_ = gl::Texture::create2D("gbuffer depth", w, h, GL_DEPTH_COMPONENT32F);
    realSurfaces_ = gl::Texture::create2D("real surface position", w, h, GL_RGBA32F);
    for (gl::Texture* t : {&position_, &normal_, &albedo_, &emissive_, &realSurfaces_})
        t->setFilter(GL_NEAREST, GL_NEAREST);
    fbo_ = gl::Framebuffer("gbuffer fbo");
    fbo_.attachColor(0, position_);
    fbo_.attachColor(1, normal_);
    fbo_.attachColor(2, albedo_);
    fbo_.attachColor(3, emissive_);
    // The fifth target, RealSurfaces, is written by the real draws only (colour mask).
    fbo_.attachColor(4, realSurfaces_);
    fbo_.attachDepth(depth_);
    fbo_.finalize(5);
    mask_ = gl::Texture::create2D("specular pixel mask", w, h, GL_DEPTH_COMPONENT32F);
    maskFbo_ = gl::Framebuffer("specular pixel mask fbo");
    maskFbo_.attachDepth(mask_);
    maskFbo_.finalize(0);
    maskDrawn_.markAll();
}

void GBufferPass::execute(FrameContext& ctx, PassResources& res) {
    fbo_.bind();
    glViewport(0, 0, ctx.canvasWidth(), ctx.canvasHeight());
    const bool separate = separateRealSurfaces(ctx);
    const float zero[4] = {0, 0, 0, 0};
    for (int i = 0; i < (separate ? 5 : 4); ++i) glClearBufferfv(GL_COLOR, i, zero);
    const float one = 1.0f;
    glClearBufferfv(GL_DEPTH, 0, &one);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    program_.use();
    ctx.bindFrameBlocks();
    ctx.scene.bindGeometry();
    const std::vector<DrawItem>& draws = ctx.scene.draws();
    const std::vector<int>& specular = ctx.scene.specularDraws();
    specularSlot_.assign(draws.size(), -1);
    for (size_t s = 0; s < specular.size(); ++s) specularSlot_[size_t(specular[s])] = int(s);
    auto drawAll = [&](bool real, bool virt) {
        for (size_t di = 0; di < draws.size(); ++di) {
            const DrawItem& d = draws[di];
            if (!(d.origin == Origin::Real ? real : virt)) continue;
            glUniform1i(locSpecularSlot_, specularSlot_[di]);
            draw_.draw(ctx.scene, d);
        }
    };
    if (separate) {
        // The real draws write RealSurfaces beside the position: once they are done it holds
        // the nearest real surface everywhere (the depth test among them is the same as without
        // the virtual ones), and the virtual draws leave it alone. Ties at equal depth between a
        // real and a virtual surface go to the real one.
        drawAll(true, false);
        glColorMaski(4, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        drawAll(false, true);
        glColorMaski(4, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        res.publish(kRealSurfaces, realSurfaces_);
    } else {
        glColorMaski(4, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        drawAll(true, true);
        glColorMaski(4, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        // Every surface is real, or no pass reads RealSurfaces this frame.
        res.publish(kRealSurfaces, position_);
    }
    if (specularInView(ctx)) {
        // The mask over the specular rectangles; outside them it stays cleared (1).
        maskFbo_.bind();
        ctx.beginFullscreen(maskProgram_, ctx.canvasWidth(), ctx.canvasHeight());
        glBindTextureUnit(kUnitMaskEmissive, emissive_.id());
        glDepthMask(GL_TRUE);  // also lets the clear write
        ctx.clearForRects(ctx.specularRects, maskDrawn_, 0, 0, true);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_ALWAYS);
        ctx.drawFullscreenTriangleIn(ctx.specularRects);
        glDepthFunc(GL_LESS);
        res.publish(kSpecularMask, mask_);
    }
    glDisable(GL_DEPTH_TEST);
    res.publish(kGBufferPosition, position_);
    res.publish(kGBufferNormal, normal_);
    res.publish(kGBufferAlbedo, albedo_);
    res.publish(kGBufferEmissive, emissive_);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeGBufferPass(const PassInit& init) {
    return std::make_unique<GBufferPass>(GBufferPass::MaterialMaps{
        init.gpuScene.hasBaseColorTextures(), init.gpuScene.hasMetallicRoughnessTextures()});
}

}  // namespace mirage::render
