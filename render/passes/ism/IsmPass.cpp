#include "render/passes/ism/IsmPass.h"

#include <cmath>

#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/passes/vpl/VplPass.h"
namespace mirage::render {

IsmPass::IsmPass() : program_(computeProgram("ism", "passes/ism/ism.comp")) {}

void IsmPass::setup(PassBuilder& b) const {
    b.read(kVpls);
    b.create(kImperfectShadowMaps, {GL_R32UI, SizeRule::IsmAtlas, Storage::PassOwned});
    b.create(kImperfectShadowMapsReal, {GL_R32UI, SizeRule::IsmAtlas, Storage::PassOwned});
}

PassDecision IsmPass::decide(const FrameContext& ctx) const {
    return {true, std::to_string(ctx.options.vpl.count) + " VPLs x " +
                      std::to_string(ctx.options.ism.pointsPerVpl) + " points" +
                      (ctx.plan.needRealOnlyIsm ? ", plus a real-only atlas"
                                                : ", no virtual points: one atlas")};
}

void IsmPass::resize(const FrameContext& ctx) {
    const int size = ismTilesPerRow(ctx.options.vpl.count) * ctx.options.ism.tileSize;
    if (size == allocatedSize_) return;
    all_ = gl::Texture::create2D("ism atlas", size, size, GL_R32UI);
    real_ = gl::Texture::create2D("ism atlas real-only", size, size, GL_R32UI);
    all_.setFilter(GL_NEAREST, GL_NEAREST);
    real_.setFilter(GL_NEAREST, GL_NEAREST);
    allocatedSize_ = size;
}

void IsmPass::execute(FrameContext& ctx, PassResources& res) {
    const GLuint far = 0x7F800000u;  // +inf as float bits: nothing splatted
    glClearTexImage(all_.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &far);
    if (ctx.plan.needRealOnlyIsm)
        glClearTexImage(real_.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &far);
    program_.use();
    ctx.bindFrameBlocks();
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingVpls, res.buffer(kVpls).id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingIsmPoints,
                     ctx.scene.surfacePointBuffer().id());
    glBindImageTexture(kImageIsmAll, all_.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    glBindImageTexture(kImageIsmReal, real_.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    glUniform1i(program_.uniformLocation("pointCount"), ctx.scene.surfacePointCount());
    glUniform1i(program_.uniformLocation("writeReal"), ctx.plan.needRealOnlyIsm ? 1 : 0);
    const float perVpl = float(std::max(1, ctx.options.ism.pointsPerVpl));
    glUniform1f(program_.uniformLocation("pointRadius"),
                std::sqrt(ctx.scene.surfaceArea() / (3.14159265f * perVpl)));
    const long long invocations = (long long)ctx.options.vpl.count * ctx.options.ism.pointsPerVpl;
    glDispatchCompute(GLuint((invocations + 63) / 64), 1, 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    res.publish(kImperfectShadowMaps, all_);
    res.publish(kImperfectShadowMapsReal, ctx.plan.needRealOnlyIsm ? real_ : all_);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeIsmPass(const PassInit&) {
    return std::make_unique<IsmPass>();
}

}  // namespace mirage::render
