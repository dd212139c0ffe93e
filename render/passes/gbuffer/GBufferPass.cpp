#include "render/passes/gbuffer/GBufferPass.h"

#include "render/FrameGraph.h"
namespace mirage::render {

GBufferPass::GBufferPass(bool metallicRoughnessMaps)
    : program_(rasterProgram(
          "gbuffer", "passes/gbuffer/gbuffer.vert", "passes/gbuffer/gbuffer.frag",
          metallicRoughnessMaps ? "#define MIRAGE_METALLIC_ROUGHNESS_MAPS 1\n" : "")) {
    locSpecularSlot_ = program_.uniformLocation("specularSlot");
}

void GBufferPass::setup(PassBuilder& b) const {
    b.write(Resource::GBufferPosition, GL_RGBA32F, SizeRule::Canvas);
    b.write(Resource::GBufferNormal, GL_RGBA16F, SizeRule::Canvas);
    b.write(Resource::GBufferAlbedo, GL_RGBA16F, SizeRule::Canvas);
    b.write(Resource::GBufferEmissive, GL_RGBA16F, SizeRule::Canvas);
}

PassDecision GBufferPass::decide(const FrameContext& ctx) const {
    if (ctx.scene.draws().empty()) return {false, "the scene has no geometry"};
    return {true, std::to_string(ctx.scene.draws().size()) + " draws"};
}

void GBufferPass::resize(const FrameContext& ctx) {
    const int w = ctx.canvasWidth(), h = ctx.canvasHeight();
    if (position_.width() == w && position_.height() == h) return;  // runs before every frame
    position_ = gl::Texture::create2D("gbuffer position", w, h, GL_RGBA32F);
    normal_ = gl::Texture::create2D("gbuffer normal", w, h, GL_RGBA16F);
    albedo_ = gl::Texture::create2D("gbuffer albedo", w, h, GL_RGBA16F);
    emissive_ = gl::Texture::create2D("gbuffer emissive", w, h, GL_RGBA16F);
    depth_ = gl::Texture::create2D("gbuffer depth", w, h, GL_DEPTH_COMPONENT32F);
    for (gl::Texture* t : {&position_, &normal_, &albedo_, &emissive_})
        t->setFilter(GL_NEAREST, GL_NEAREST);
    fbo_ = gl::Framebuffer("gbuffer fbo");
    fbo_.attachColor(0, position_);
    fbo_.attachColor(1, normal_);
    fbo_.attachColor(2, albedo_);
    fbo_.attachColor(3, emissive_);
    fbo_.attachDepth(depth_);
    fbo_.finalize(4);
}

void GBufferPass::execute(FrameContext& ctx, PassResources& res) {
    fbo_.bind();
    glViewport(0, 0, ctx.canvasWidth(), ctx.canvasHeight());
    const float zero[4] = {0, 0, 0, 0};
    for (int i = 0; i < 4; ++i) glClearBufferfv(GL_COLOR, i, zero);
    const float one = 1.0f;
    glClearBufferfv(GL_DEPTH, 0, &one);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    program_.use();
    ctx.bindFrameBlocks();
    ctx.scene.bindGeometry();
    const std::vector<int>& specular = ctx.scene.specularDraws();
    size_t nextSpecular = 0;  // specularDraws() is in draw order
    for (size_t di = 0; di < ctx.scene.draws().size(); ++di) {
        const DrawItem& d = ctx.scene.draws()[di];
        int slot = -1;
        if (nextSpecular < specular.size() && specular[nextSpecular] == int(di))
            slot = int(nextSpecular++);
        glUniform1i(locSpecularSlot_, slot);
        draw_.draw(ctx.scene, d);
    }
    glDisable(GL_DEPTH_TEST);
    res.publish(Resource::GBufferPosition, position_);
    res.publish(Resource::GBufferNormal, normal_);
    res.publish(Resource::GBufferAlbedo, albedo_);
    res.publish(Resource::GBufferEmissive, emissive_);
}

}  // namespace mirage::render
