#include "render/passes/ism/IsmPass.h"

#include <cmath>

#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/passes/vpl/VplPass.h"
namespace mirage::render {

IsmPass::IsmPass()
    : program_(computeProgram("ism", "passes/ism/ism.comp")),
      pullPush_(computeProgram("ism pull-push", "passes/ism/ism_pullpush.comp")) {}

int IsmPass::pullPushLevels(int tileSize) {
    int levels = 0;
    while ((tileSize >> levels) % 2 == 0 && (tileSize >> (levels + 1)) >= 4) ++levels;
    return levels;
}

void IsmPass::setup(PassBuilder& b) const {
    b.read(kVpls);
    b.create(kImperfectShadowMaps, {GL_R32UI, SizeRule::IsmAtlas, Storage::PassOwned});
    b.create(kImperfectShadowMapsReal, {GL_R32UI, SizeRule::IsmAtlas, Storage::PassOwned});
}

PassDecision IsmPass::decide(const FrameContext& ctx) const {
    return {true,
            std::to_string(ctx.options.vpl.count) + " VPLs x " +
                std::to_string(ctx.options.ism.pointsPerVpl) + " points" +
                (ctx.plan.needRealOnlyIsm ? ", plus a real-only atlas"
                                          : ", no virtual points: one atlas") +
                (ctx.options.ism.pullPush && pullPushLevels(ctx.options.ism.tileSize) > 0
                     ? ", gaps filled by pull-push (" +
                           std::to_string(pullPushLevels(ctx.options.ism.tileSize)) + " levels)"
                     : "")};
}

void IsmPass::resize(const FrameContext& ctx) {
    const int size = ismTilesPerRow(ctx.options.vpl.count) * ctx.options.ism.tileSize;
    const int levels = ctx.options.ism.pullPush ? pullPushLevels(ctx.options.ism.tileSize) : 0;
    if (levels != allocatedLevels_ || size != allocatedSize_) {
        pyramid_ = levels > 0 ? gl::Texture::create2D("ism pull-push pyramid", size / 2, size / 2,
                                                      GL_RG32F, levels)
                              : gl::Texture();
        allocatedLevels_ = levels;
    }
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
    if (allocatedLevels_ > 0) {
        pullPush(ctx, all_);
        if (ctx.plan.needRealOnlyIsm) pullPush(ctx, real_);
    }
    res.publish(kImperfectShadowMaps, all_);
    res.publish(kImperfectShadowMapsReal, ctx.plan.needRealOnlyIsm ? real_ : all_);
}

void IsmPass::pullPush(const FrameContext& ctx, const gl::Texture& atlas) {
    pullPush_.use();
    ctx.bindFrameBlocks();
    const GLint locMode = pullPush_.uniformLocation("mode");
    const GLint locSize = pullPush_.uniformLocation("levelSize");
    glUniform1f(pullPush_.uniformLocation("minCoverage"), ctx.options.ism.pullPushCoverage);
    glBindImageTexture(kImageIsmAll, atlas.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    // One dispatch per level; each reads what the one before wrote.
    auto run = [&](int mode, int srcMip, int dstMip, int level) {
        const int n = allocatedSize_ >> level;
        if (srcMip >= 0)
            glBindImageTexture(kImageIsmPyramidSrc, pyramid_.id(), srcMip, GL_FALSE, 0,
                               GL_READ_ONLY, GL_RG32F);
        if (dstMip >= 0)
            glBindImageTexture(kImageIsmPyramidDst, pyramid_.id(), dstMip, GL_FALSE, 0,
                               GL_READ_WRITE, GL_RG32F);
        glUniform1i(locMode, mode);
        glUniform2i(locSize, n, n);
        glDispatchCompute(GLuint((n + 7) / 8), GLuint((n + 7) / 8), 1);
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    };
    // Pyramid level L (L >= 1) is mip L - 1.
    run(0, -1, 0, 1);
    for (int level = 2; level <= allocatedLevels_; ++level) run(1, level - 2, level - 1, level);
    for (int level = allocatedLevels_ - 1; level >= 1; --level) run(2, level, level - 1, level);
    run(3, 0, -1, 0);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeIsmPass(const PassInit&) {
    return std::make_unique<IsmPass>();
}

}  // namespace mirage::render
