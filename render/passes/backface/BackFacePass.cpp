#include "render/passes/backface/BackFacePass.h"

#include "render/FrameGraph.h"
#include "render/PassRegistry.h"

namespace mirage::render {

BackFacePass::BackFacePass()
    : program_(rasterProgram("backface", "passes/gbuffer/gbuffer.vert",
                             "passes/backface/backface.frag")) {
    locModel_ = program_.uniformLocation("model");
    locNormal_ = program_.uniformLocation("normalMatrix");
    locSlot_ = program_.uniformLocation("specularSlot");
}

void BackFacePass::setup(PassBuilder& b) const {
    b.create(kBackFacePosition, {GL_RGBA32F, SizeRule::Canvas, Storage::PassOwned});
    b.create(kBackFaceNormal, {GL_RGBA16F, SizeRule::Canvas, Storage::PassOwned});
}

PassDecision BackFacePass::decide(const FrameContext& ctx) const {
    const size_t n = ctx.scene.specularDraws().size();
    if (n == 0) return {false, "no mirror or glass object in the scene"};
    // The specular passes after this one need the back faces, so they are skipped with it.
    const glm::ivec4 r = ctx.specularScissor;
    if (r.z <= 0 || r.w <= 0) return {false, "no mirror or glass object in view"};
    const double share = 100.0 * double(r.z) * double(r.w) /
                         (double(ctx.canvasWidth()) * double(ctx.canvasHeight()));
    return {true, std::to_string(n) + " specular draw(s) within " + std::to_string(r.z) + "x" +
                      std::to_string(r.w) + " canvas pixels (" + std::to_string(int(share + 0.5)) +
                      " %)"};
}

void BackFacePass::resize(const FrameContext& ctx) {
    const int w = ctx.canvasWidth(), h = ctx.canvasHeight();
    if (w == width_ && h == height_) return;
    width_ = w;
    height_ = h;
    position_ = gl::Texture::create2D("backface position", w, h, GL_RGBA32F);
    normal_ = gl::Texture::create2D("backface normal", w, h, GL_RGBA16F);
    depth_ = gl::Texture::create2D("backface depth", w, h, GL_DEPTH_COMPONENT32F);
    for (gl::Texture* t : {&position_, &normal_}) t->setFilter(GL_NEAREST, GL_NEAREST);
    fbo_ = gl::Framebuffer("backface fbo");
    fbo_.attachColor(0, position_);
    fbo_.attachColor(1, normal_);
    fbo_.attachDepth(depth_);
    fbo_.finalize(2);
    drawn_.markAll();
}

void BackFacePass::execute(FrameContext& ctx, PassResources& res) {
    glViewport(0, 0, ctx.canvasWidth(), ctx.canvasHeight());
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);  // back faces are selected by their normal in the shader
    glDisable(GL_BLEND);
    program_.use();
    ctx.bindFrameBlocks();
    ctx.scene.bindGeometry();
    auto draw = [&](const DrawItem& d, int slot) {
        glUniformMatrix4fv(locModel_, 1, GL_FALSE, &d.model[0][0]);
        glUniformMatrix4fv(locNormal_, 1, GL_FALSE, &d.normalMatrix[0][0]);
        glUniform1i(locSlot_, slot);
        ctx.scene.drawItem(d);
    };

    fbo_.bind();
    // Every specular draw's fragments lie in its rectangle (FrameContext::specularRects).
    glDepthMask(GL_TRUE);
    ctx.clearForRects(ctx.specularRects, drawn_, 0, 2, true);
    const std::vector<int>& spec = ctx.scene.specularDraws();
    for (size_t s = 0; s < spec.size(); ++s) draw(ctx.scene.draws()[size_t(spec[s])], int(s));
    res.publish(kBackFacePosition, position_);
    res.publish(kBackFaceNormal, normal_);
    glDisable(GL_DEPTH_TEST);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeBackFacePass(const PassInit&) {
    return std::make_unique<BackFacePass>();
}

}  // namespace mirage::render
