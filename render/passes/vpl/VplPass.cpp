#include "render/passes/vpl/VplPass.h"

#include <cmath>

#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/passes/caustic/PhotonGBufferPass.h"
#include "render/passes/shadow/ShadowPass.h"
namespace mirage::render {

VplPass::VplPass() : program_(computeProgram("vpl", "passes/vpl/vpl.comp")) {}

void VplPass::setup(PassBuilder& b) const {
    b.read(kRsmFlux);
    b.read(kRsmNormal);
    b.read(kRsmPosition);
    // Reflected / refracted VPLs follow the photons (none: no caustic light, or the option off).
    for (Resource r : {kPhotonHitRefl, kPhotonPowerRefl, kPhotonSurfaceRefl, kPhotonHitRefr,
                       kPhotonPowerRefr, kPhotonSurfaceRefr})
        b.readOptional(r);
    b.createBuffer(kVpls, SizeRule::Vpl);
}

glm::vec2 vplSampleOffset(int frame) {
    // The R2 sequence (Roberts 2018): the plastic number's powers, offsets that fill the unit
    // square evenly for any number of consecutive frames.
    constexpr double g = 1.32471795724474602596;
    const double n = double(frame);
    return {float(std::fmod(n / g, 1.0)), float(std::fmod(n / (g * g), 1.0))};
}

bool VplPass::staticThisFrame(const FrameContext& ctx) const {
    return !ctx.options.vpl.temporalRotation;
}

PassDecision VplPass::decide(const FrameContext& ctx) const {
    if (!ctx.plan.needVpls) return {false, ctx.plan.vplReason};
    std::string reason = ctx.plan.vplReason;
    if (ctx.plan.causticLayers > 0)
        reason += ctx.options.vpl.throughSpecular
                      ? "; VPLs on mirror / glass follow the reflected / refracted photons"
                      : "; reflected / refracted VPLs off";
    if (ctx.options.vpl.temporalRotation) reason += "; the Hammersley set rotated every frame";
    return {true, reason};
}

void VplPass::resize(const FrameContext& ctx) {
    const int n = std::max(1, ctx.options.vpl.count);
    if (n == allocated_) return;
    vpls_ = gl::Buffer("vpls", size_t(n) * sizeof(GpuVpl));
    allocated_ = n;
}

void VplPass::execute(FrameContext& ctx, PassResources& res) {
    program_.use();
    ctx.bindFrameBlocks();
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingVpls, vpls_.id());
    glBindTextureUnit(kUnitVplRsmFlux, res.texture(kRsmFlux).id());
    glBindTextureUnit(kUnitVplRsmNormal, res.texture(kRsmNormal).id());
    glBindTextureUnit(kUnitVplRsmPosition, res.texture(kRsmPosition).id());
    const bool follow = ctx.options.vpl.throughSpecular && res.has(kPhotonHitRefl);
    const Resource photons[6] = {kPhotonHitRefl, kPhotonPowerRefl, kPhotonSurfaceRefl,
                                 kPhotonHitRefr, kPhotonPowerRefr, kPhotonSurfaceRefr};
    const int units[6] = {kUnitVplPhotonHitRefl,     kUnitVplPhotonPowerRefl,
                          kUnitVplPhotonSurfaceRefl, kUnitVplPhotonHitRefr,
                          kUnitVplPhotonPowerRefr,   kUnitVplPhotonSurfaceRefr};
    // Without photons the shader never samples these units (every layer is -1).
    for (int i = 0; i < 6; ++i)
        glBindTextureUnit(GLuint(units[i]), follow ? res.texture(photons[i]).id() : 0);
    glm::ivec4 ranges[kMaxLights] = {};
    glm::mat4 causticViewProj[kMaxLights];
    float causticTanHalf[kMaxLights] = {};
    for (size_t i = 0; i < ctx.plan.lights.size(); ++i) {
        const LightPlan& lp = ctx.plan.lights[i];
        const int photonLayer = follow && lp.caustics ? lp.causticLayer : -1;
        ranges[i] = glm::ivec4(lp.firstVpl, lp.vplCount, lp.hasRsm ? 1 : 0, photonLayer);
        causticViewProj[i] = lp.causticViewProj;
        causticTanHalf[i] = lp.causticTanHalf;
    }
    glUniform4iv(program_.uniformLocation("lightVplFirst"), kMaxLights, &ranges[0][0]);
    glUniformMatrix4fv(program_.uniformLocation("causticViewProj"), kMaxLights, GL_FALSE,
                       &causticViewProj[0][0][0]);
    glUniform1fv(program_.uniformLocation("causticTanHalf"), kMaxLights, causticTanHalf);
    glUniform1i(program_.uniformLocation("photonMapSize"), ctx.options.caustic.mapSize);
    const int frame = ctx.options.vpl.temporalRotation ? ctx.frameIndex : 0;
    glUniform2fv(program_.uniformLocation("sampleOffset"), 1, &vplSampleOffset(frame)[0]);
    glUniform1i(program_.uniformLocation("haltonFrame"), frame);
    glDispatchCompute(GLuint((ctx.options.vpl.count + 63) / 64), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    res.publish(kVpls, vpls_);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeVplPass(const PassInit&) {
    return std::make_unique<VplPass>();
}

}  // namespace mirage::render
