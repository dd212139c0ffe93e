#include "render/passes/vpl/VplPass.h"

#include "render/Shaders.h"
#include "render/passes/shadow/ShadowPass.h"

namespace mirage::render {

VplPass::VplPass(const ShadowPass& shadow)
    : shadow_(shadow),
      program_("vpl", {{GL_COMPUTE_SHADER, "passes/vpl/vpl.comp",
                        shaders::source("passes/vpl/vpl.comp")}}) {}

PassDecision VplPass::decide(const FrameContext& ctx) const {
    return {ctx.plan.needVpls, ctx.plan.vplReason};
}

void VplPass::resize(const FrameContext& ctx) {
    const int n = std::max(1, ctx.options.vplCount);
    if (n == allocated_) return;
    vpls_ = gl::Buffer("vpls", size_t(n) * sizeof(GpuVpl));
    allocated_ = n;
}

void VplPass::execute(FrameContext& ctx) {
    program_.use();
    ctx.bindFrameBlocks();
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingVpls, vpls_.id());
    glBindTextureUnit(0, shadow_.rsmFlux().id());
    glBindTextureUnit(1, shadow_.rsmNormal().id());
    glBindTextureUnit(2, shadow_.rsmPosition().id());
    glm::ivec4 ranges[kMaxLights] = {};
    for (size_t i = 0; i < ctx.plan.lights.size(); ++i) {
        const LightPlan& lp = ctx.plan.lights[i];
        ranges[i] = glm::ivec4(lp.firstVpl, lp.vplCount, lp.hasRsm ? 1 : 0, 0);
    }
    glUniform4iv(program_.uniformLocation("lightVplFirst"), kMaxLights, &ranges[0][0]);
    glDispatchCompute(GLuint((ctx.options.vplCount + 63) / 64), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    publishCached(ctx);
}

void VplPass::publishCached(FrameContext& ctx) {
    ctx.publish(Resource::Vpls, nullptr);
}

}  // namespace mirage::render
