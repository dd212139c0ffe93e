#include "render/passes/caustic/PhotonGBufferPass.h"

#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/passes/impostor/ImpostorPass.h"
#include "render/passes/shadow/ShadowPass.h"

namespace mirage::render {

PhotonGBufferPass::PhotonGBufferPass(const GpuScene& scene)
    : backProgram_(rasterProgram("photon back faces", "passes/shadow/shadow.vert",
                                 "passes/caustic/photon_backface.frag")),
      photonProgram_(rasterProgram("photon gbuffer", "passes/shadow/shadow.vert",
                                   "passes/caustic/photon_gbuffer.frag", scene.lightingDefines())),
      backFbo_("photon back-face fbo"),
      photonFbo_("photon gbuffer fbo") {}

void PhotonGBufferPass::setup(PassBuilder& b) const {
    ImpostorPass::declareTracing(b);
    b.readOptional(kShadowMaps);  // light visibility of the photons' first surface
    b.readOptional(kShadowMapsReal);
    b.create(kPhotonHitRefl, {GL_RGBA32F, SizeRule::CausticMap, Storage::PassOwned});
    b.create(kPhotonPowerRefl, {GL_RGBA32F, SizeRule::CausticMap, Storage::PassOwned});
    b.create(kPhotonHitRefr, {GL_RGBA32F, SizeRule::CausticMap, Storage::PassOwned});
    b.create(kPhotonPowerRefr, {GL_RGBA32F, SizeRule::CausticMap, Storage::PassOwned});
    b.create(kPhotonSurfaceRefl, {GL_RGBA32UI, SizeRule::CausticMap, Storage::PassOwned});
    b.create(kPhotonSurfaceRefr, {GL_RGBA32UI, SizeRule::CausticMap, Storage::PassOwned});
}

PassDecision PhotonGBufferPass::decide(const FrameContext& ctx) const {
    if (ctx.plan.causticLayers == 0) return {false, ctx.plan.causticReason};
    const int s = ctx.options.caustic.mapSize;
    return {true, ctx.plan.causticReason + ": " + std::to_string(s) + "^2 photons each"};
}

void PhotonGBufferPass::resize(const FrameContext& ctx) {
    const int s = ctx.options.caustic.mapSize, layers = std::max(1, ctx.plan.causticLayers);
    if (s == allocatedSize_ && layers == allocatedLayers_) return;
    backPosition_ = gl::Texture::create2D("photon back-face position", s, s, GL_RGBA32F);
    backNormal_ = gl::Texture::create2D("photon back-face normal", s, s, GL_RGBA16F);
    depth_ = gl::Texture::create2D("photon depth", s, s, GL_DEPTH_COMPONENT32F);
    reflHit_ = gl::Texture::create2DArray("PGBuf_refl hit", s, s, layers, GL_RGBA32F);
    reflPower_ = gl::Texture::create2DArray("PGBuf_refl power", s, s, layers, GL_RGBA32F);
    refrHit_ = gl::Texture::create2DArray("PGBuf_refr hit", s, s, layers, GL_RGBA32F);
    refrPower_ = gl::Texture::create2DArray("PGBuf_refr power", s, s, layers, GL_RGBA32F);
    reflSurface_ = gl::Texture::create2DArray("PGBuf_refl receiver", s, s, layers, GL_RGBA32UI);
    refrSurface_ = gl::Texture::create2DArray("PGBuf_refr receiver", s, s, layers, GL_RGBA32UI);
    for (gl::Texture* t : {&backPosition_, &backNormal_, &reflHit_, &reflPower_, &refrHit_,
                           &refrPower_, &reflSurface_, &refrSurface_})
        t->setFilter(GL_NEAREST, GL_NEAREST);
    backFbo_ = gl::Framebuffer("photon back-face fbo");
    backFbo_.attachColor(0, backPosition_);
    backFbo_.attachColor(1, backNormal_);
    backFbo_.attachDepth(depth_);
    backFbo_.finalize(2);
    allocatedSize_ = s;
    allocatedLayers_ = layers;
}

void PhotonGBufferPass::execute(FrameContext& ctx, PassResources& res) {
    const int s = allocatedSize_;
    const GpuScene& scene = ctx.scene;
    glViewport(0, 0, s, s);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    scene.bindGeometry();
    scene.bindTableTexels(sceneTables_, kUnitPhotonMaterials, kUnitPhotonSpecularDraws);
    ImpostorPass::bindForTracing(res, impostorTables_);  // kUnitImpostor*, the header block
    const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f}, one = 1.0f;
    for (size_t li = 0; li < ctx.plan.lights.size(); ++li) {
        const LightPlan& lp = ctx.plan.lights[li];
        if (!lp.caustics) continue;
        // The light's nearest back faces of the specular objects (the refracted photons' exit).
        backFbo_.bind();
        glClearBufferfv(GL_COLOR, 0, zero);
        glClearBufferfv(GL_COLOR, 1, zero);
        glClearBufferfv(GL_DEPTH, 0, &one);
        backProgram_.use();
        ctx.bindFrameBlocks();
        glUniformMatrix4fv(backProgram_.uniformLocation("lightViewProj"), 1, GL_FALSE,
                           &lp.causticViewProj[0][0]);
        glUniform1i(backProgram_.uniformLocation("lightIndex"), int(li));
        const GLint locModel = backProgram_.uniformLocation("model");
        const GLint locNormal = backProgram_.uniformLocation("normalMatrix");
        const GLint locSlot = backProgram_.uniformLocation("specularSlot");
        const std::vector<int>& spec = scene.specularDraws();
        for (size_t slot = 0; slot < spec.size(); ++slot) {
            const DrawItem& d = scene.draws()[size_t(spec[slot])];
            glUniformMatrix4fv(locModel, 1, GL_FALSE, &d.model[0][0]);
            glUniformMatrix4fv(locNormal, 1, GL_FALSE, &d.normalMatrix[0][0]);
            glUniform1i(locSlot, int(slot));
            scene.drawItem(d);
        }
        // The photons: the nearest specular surface per texel.
        photonFbo_.attachColorLayer(0, reflHit_, lp.causticLayer);
        photonFbo_.attachColorLayer(1, reflPower_, lp.causticLayer);
        photonFbo_.attachColorLayer(2, refrHit_, lp.causticLayer);
        photonFbo_.attachColorLayer(3, refrPower_, lp.causticLayer);
        photonFbo_.attachColorLayer(4, reflSurface_, lp.causticLayer);
        photonFbo_.attachColorLayer(5, refrSurface_, lp.causticLayer);
        photonFbo_.attachDepth(depth_);
        photonFbo_.finalize(6);
        photonFbo_.bind();
        for (int i = 0; i < 4; ++i) glClearBufferfv(GL_COLOR, i, zero);
        const GLuint zeroU[4] = {0u, 0u, 0u, 0u};
        for (int i = 4; i < 6; ++i) glClearBufferuiv(GL_COLOR, i, zeroU);
        glClearBufferfv(GL_DEPTH, 0, &one);
        photonProgram_.use();
        ctx.bindFrameBlocks();
        glBindTextureUnit(kUnitPhotonBackPosition, backPosition_.id());
        glBindTextureUnit(kUnitPhotonBackNormal, backNormal_.id());
        glBindTextureUnit(kUnitPhotonShadowAll,
                          res.textureOr(kShadowMaps, ctx.farShadowTexture()).id());
        glBindTextureUnit(kUnitPhotonShadowReal,
                          res.textureOr(kShadowMapsReal, ctx.farShadowTexture()).id());
        glUniformMatrix4fv(photonProgram_.uniformLocation("lightViewProj"), 1, GL_FALSE,
                           &lp.causticViewProj[0][0]);
        glUniform1i(photonProgram_.uniformLocation("lightIndex"), int(li));
        glUniform1f(photonProgram_.uniformLocation("mapSize"), float(s));
        glUniform1f(photonProgram_.uniformLocation("tanHalf"), lp.causticTanHalf);
        glUniform1i(photonProgram_.uniformLocation("marchSteps"),
                    ctx.options.specular.refractionMarchSteps);
        glUniform1i(photonProgram_.uniformLocation("roughPhotons"),
                    ctx.options.caustic.roughLobes ? 1 : 0);
        const GLint locPhotonSlot = photonProgram_.uniformLocation("specularSlot");
        for (size_t slot = 0; slot < spec.size(); ++slot) {
            glUniform1i(locPhotonSlot, int(slot));
            photonDraw_.draw(scene, scene.draws()[size_t(spec[slot])]);
        }
    }
    glDisable(GL_DEPTH_TEST);
    res.publish(kPhotonHitRefl, reflHit_);
    res.publish(kPhotonPowerRefl, reflPower_);
    res.publish(kPhotonHitRefr, refrHit_);
    res.publish(kPhotonPowerRefr, refrPower_);
    res.publish(kPhotonSurfaceRefl, reflSurface_);
    res.publish(kPhotonSurfaceRefr, refrSurface_);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makePhotonGBufferPass(const PassInit& init) {
    return std::make_unique<PhotonGBufferPass>(init.gpuScene);
}

}  // namespace mirage::render
