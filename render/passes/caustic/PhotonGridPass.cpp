#include "render/passes/caustic/PhotonGridPass.h"

#include <fmt/format.h>

#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/passes/caustic/PhotonGBufferPass.h"

namespace mirage::render {

PhotonGridPass::PhotonGridPass()
    : count_(computeProgram("photon grid count", "passes/caustic/photon_grid_count.comp")),
      scan_(computeProgram("photon grid scan", "passes/caustic/photon_grid_scan.comp")),
      scatter_(computeProgram("photon grid scatter", "passes/caustic/photon_grid_scatter.comp")),
      grid_("photon grid", (2 * size_t(kPhotonGridSlots) + 1) * sizeof(GLuint)) {}

void PhotonGridPass::setup(PassBuilder& b) const {
    for (Resource r : {kPhotonHitRefl, kPhotonPowerRefl, kPhotonSurfaceRefl, kPhotonHitRefr,
                       kPhotonPowerRefr, kPhotonSurfaceRefr})
        b.read(r);
    b.createBuffer(kPhotonGrid, SizeRule::CausticMap);
    b.createBuffer(kPhotonRecords, SizeRule::CausticMap);
}

PassDecision PhotonGridPass::gatherDecision(const FrameContext& ctx) {
    if (ctx.plan.causticLayers == 0) return {false, ctx.plan.causticReason};
    if (!ctx.options.caustic.gather) return {false, "caustic gather off"};
    if (ctx.specularScissor.z <= 0 || ctx.specularScissor.w <= 0)
        return {false, "no mirror or glass object in view: no reflected or refracted hit"};
    return {true, "the photons of " + std::to_string(ctx.plan.causticLayers) +
                      " light(s), for the reflected / refracted hits in view"};
}

bool PhotonGridPass::sceneCanGather(const GpuScene& scene, const RendererOptions& options) {
    if (!options.caustic.enabled || !options.caustic.gather || scene.specularDraws().empty())
        return false;
    for (const SceneLight& l : scene.lights())
        if (l.type == kLightSpot) return true;
    return false;
}

PassDecision PhotonGridPass::decide(const FrameContext& ctx) const {
    PassDecision d = gatherDecision(ctx);
    if (d.run)
        d.reason = fmt::format("{}: hashed grid of {} buckets, {:.3g} cm cells", d.reason,
                               kPhotonGridCells, 100.0 * cellSize(ctx.options));
    return d;
}

void PhotonGridPass::resize(const FrameContext& ctx) {
    const size_t s = size_t(ctx.options.caustic.mapSize);
    const size_t n = s * s * 2 * size_t(std::max(1, ctx.plan.causticLayers));
    if (n == capacity_) return;
    records_ = gl::Buffer("photon records", n * sizeof(GpuPhoton));
    capacity_ = n;
    // The counts start at zero (the scatter step counts them back down after every build).
    const GLuint zero = 0;
    glClearNamedBufferData(grid_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
}

void PhotonGridPass::execute(FrameContext& ctx, PassResources& res) {
    const int s = ctx.options.caustic.mapSize;
    const GLuint groups = GLuint((s + 7) / 8), layers = GLuint(2 * ctx.plan.causticLayers);
    const float cell = cellSize(ctx.options);
    glBindTextureUnit(kUnitGridReflHit, res.texture(kPhotonHitRefl).id());
    glBindTextureUnit(kUnitGridReflPower, res.texture(kPhotonPowerRefl).id());
    glBindTextureUnit(kUnitGridReflSurface, res.texture(kPhotonSurfaceRefl).id());
    glBindTextureUnit(kUnitGridRefrHit, res.texture(kPhotonHitRefr).id());
    glBindTextureUnit(kUnitGridRefrPower, res.texture(kPhotonPowerRefr).id());
    glBindTextureUnit(kUnitGridRefrSurface, res.texture(kPhotonSurfaceRefr).id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingPhotonGrid, grid_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingPhotons, records_.id());

    count_.use();
    glUniform1i(count_.uniformLocation("mapSize"), s);
    glUniform1f(count_.uniformLocation("cellSize"), cell);
    glDispatchCompute(groups, groups, layers);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

    scan_.use();
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

    scatter_.use();
    glUniform1i(scatter_.uniformLocation("mapSize"), s);
    glUniform1f(scatter_.uniformLocation("cellSize"), cell);
    glUniform1f(scatter_.uniformLocation("quadScale"), ctx.options.caustic.quadScale);
    glUniform1ui(scatter_.uniformLocation("capacity"), GLuint(capacity_));
    glDispatchCompute(groups, groups, layers);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    res.publish(kPhotonGrid, grid_);
    res.publish(kPhotonRecords, records_);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makePhotonGridPass(const PassInit&) {
    return std::make_unique<PhotonGridPass>();
}

}  // namespace mirage::render
