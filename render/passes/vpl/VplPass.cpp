#include "render/passes/vpl/VplPass.h"

#include "render/FrameGraph.h"
namespace mirage::render {

VplPass::VplPass() : program_(computeProgram("vpl", "passes/vpl/vpl.comp")) {}

void VplPass::setup(PassBuilder& b) const {
    b.read(Resource::RsmFlux);
    b.read(Resource::RsmNormal);
    b.read(Resource::RsmPosition);
    b.writeBuffer(Resource::Vpls, SizeRule::Vpl);
}

PassDecision VplPass::decide(const FrameContext& ctx) const {
    return {ctx.plan.needVpls, ctx.plan.vplReason};
}

void VplPass::resize(const FrameContext& ctx) {
    const int n = std::max(1, ctx.options.vplCount);
    if (n == allocated_) return;
    vpls_ = gl::Buffer("vpls", size_t(n) * sizeof(GpuVpl));
    allocated_ = n;
}

void VplPass::execute(FrameContext& ctx, PassResources& res) {
    program_.use();
    ctx.bindFrameBlocks();
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingVpls, vpls_.id());
    glBindTextureUnit(kUnitVplRsmFlux, res.texture(Resource::RsmFlux).id());
    glBindTextureUnit(kUnitVplRsmNormal, res.texture(Resource::RsmNormal).id());
    glBindTextureUnit(kUnitVplRsmPosition, res.texture(Resource::RsmPosition).id());
    glm::ivec4 ranges[kMaxLights] = {};
    for (size_t i = 0; i < ctx.plan.lights.size(); ++i) {
        const LightPlan& lp = ctx.plan.lights[i];
        ranges[i] = glm::ivec4(lp.firstVpl, lp.vplCount, lp.hasRsm ? 1 : 0, 0);
    }
    glUniform4iv(program_.uniformLocation("lightVplFirst"), kMaxLights, &ranges[0][0]);
    glDispatchCompute(GLuint((ctx.options.vplCount + 63) / 64), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    res.publish(Resource::Vpls, vpls_);
}

}  // namespace mirage::render
