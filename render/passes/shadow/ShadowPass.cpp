#include "render/passes/shadow/ShadowPass.h"

#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/translucency/VoxelNumberMap.h"
namespace mirage::render {

ShadowPass::ShadowPass()
    : program_(rasterProgram("shadow", "passes/shadow/shadow.vert", "passes/shadow/shadow.frag")),
      glassProgram_(rasterProgram("shadow glass", "passes/shadow/shadow.vert",
                                  "passes/shadow/shadow_glass.frag")),
      fbo_("shadow fbo"),
      glassFbo_("shadow glass fbo"),
      rsmFbo_("rsm fbo") {
    locViewProj_ = program_.uniformLocation("lightViewProj");
    locLight_ = program_.uniformLocation("lightIndex");
    locGlassLayer_ = program_.uniformLocation("glassLayer");
    locGlassScale_ = program_.uniformLocation("glassTexelsPerTexel");
    locGlassViewProj_ = glassProgram_.uniformLocation("lightViewProj");
    locGlassLight_ = glassProgram_.uniformLocation("lightIndex");
    locTranslucent_ = glassProgram_.uniformLocation("translucent");
    locExtinction_ = glassProgram_.uniformLocation("mediumExtinction");
    locShadowScale_ = glassProgram_.uniformLocation("mediumShadowScale");
    locIor_ = glassProgram_.uniformLocation("mediumIor");
    locHasDensity_ = glassProgram_.uniformLocation("mediumHasDensity");
    locLocalFromWorld_ = glassProgram_.uniformLocation("mediumLocalFromWorld");
    locDensityMin_ = glassProgram_.uniformLocation("densityMin");
    locDensityMax_ = glassProgram_.uniformLocation("densityMax");
    locDensityCells_ = glassProgram_.uniformLocation("densityCells");
}

void ShadowPass::setup(PassBuilder& b) const {
    b.create(kShadowMaps, {GL_R32F, SizeRule::FocusedShadowAtlas, Storage::PassOwned});
    b.create(kShadowMapsReal, {GL_R32F, SizeRule::ShadowAtlas, Storage::PassOwned});
    b.create(kShadowGlass,
             {GL_RGBA32F, SizeRule::ShadowAtlas, Storage::PassOwned});  // only with glass in a cone
    b.create(kShadowGlassReal, {GL_RGBA32F, SizeRule::ShadowAtlas, Storage::PassOwned});
    b.create(kRsmFlux,
             {GL_RGBA16F, SizeRule::RsmAtlas, Storage::PassOwned});  // only when VPLs are needed
    b.create(kRsmNormal, {GL_RGBA16F, SizeRule::RsmAtlas, Storage::PassOwned});
    b.create(kRsmPosition, {GL_RGBA32F, SizeRule::RsmAtlas, Storage::PassOwned});
}

PassDecision ShadowPass::decide(const FrameContext& ctx) const {
    if (ctx.plan.shadowLayers == 0) return {false, "no light has a shadow caster in its cone"};
    int n = 0, real = 0, focused = 0, glass = 0, translucent = 0;
    for (const LightPlan& l : ctx.plan.lights) {
        n += l.castsShadow;
        real += l.needsRealOnlyMap;
        focused += int(l.focusDraws.size());
        glass += l.glassTransmits;
        translucent += l.translucentTransmits;
    }
    return {true,
            std::to_string(n) + " light(s) with casters in the cone, " +
                std::to_string(ctx.plan.shadowLayers) + " layer(s); " + std::to_string(real) +
                " need a real-only map" +
                (focused ? "; " + std::to_string(focused) + " focused virtual-occluder map(s)"
                         : std::string()) +
                (glass ? "; glass transmits in " + std::to_string(glass) : std::string()) +
                (translucent ? "; a translucent object transmits in " + std::to_string(translucent)
                             : std::string()) +
                (ctx.plan.needVpls ? "; RSMs for VPLs" : "")};
}

void ShadowPass::resize(const FrameContext& ctx) {
    const int layers = std::max(1, ctx.plan.shadowLayers), s = ctx.options.shadow.mapSize,
              r = ctx.options.shadow.rsmSize, focus = ctx.plan.focusLayers;
    if (layers == allocatedLayers_ && focus == allocatedFocusLayers_ && s == allocatedSize_ &&
        r == rsmSize_)
        return;
    distance_ = gl::Texture::create2DArray("shadow distance", s, s, layers + focus, GL_R32F);
    distanceReal_ = gl::Texture::create2DArray("shadow distance real-only", s, s, layers, GL_R32F);
    rsmFlux_ = gl::Texture::create2DArray("rsm flux", r, r, layers, GL_RGBA16F);
    rsmNormal_ = gl::Texture::create2DArray("rsm normal", r, r, layers, GL_RGBA16F);
    rsmPosition_ = gl::Texture::create2DArray("rsm position", r, r, layers, GL_RGBA32F);
    for (gl::Texture* t : {&distance_, &distanceReal_, &rsmFlux_, &rsmNormal_, &rsmPosition_})
        t->setFilter(GL_NEAREST, GL_NEAREST);
    glass_ = gl::Texture::create2DArray("shadow glass", s, s, layers, GL_RGBA32F);
    glassReal_ = gl::Texture::create2DArray("shadow glass real-only", s, s, layers, GL_RGBA32F);
    glass_.setFilter(GL_NEAREST, GL_NEAREST);
    glassReal_.setFilter(GL_NEAREST, GL_NEAREST);
    depth_ = gl::Texture::create2D("shadow depth", s, s, GL_DEPTH_COMPONENT32F);
    rsmDepth_ =
        r == s ? gl::Texture() : gl::Texture::create2D("rsm depth", r, r, GL_DEPTH_COMPONENT32F);
    allocatedLayers_ = layers;
    allocatedFocusLayers_ = focus;
    allocatedSize_ = s;
    rsmSize_ = r;
}

// Attaches layer atlasLayer of `distance` (and of the RSM atlases when `rsm`) to the raster
// and clears it to "no occluder".
void ShadowPass::beginLayer(const gl::Texture& distance, int atlasLayer, bool rsm) {
    fbo_.attachColorLayer(0, distance, atlasLayer);
    const int colorCount = rsm ? 4 : 1;
    if (rsm) {
        fbo_.attachColorLayer(1, rsmFlux_, atlasLayer);
        fbo_.attachColorLayer(2, rsmNormal_, atlasLayer);
        fbo_.attachColorLayer(3, rsmPosition_, atlasLayer);
    } else {
        for (int i = 1; i < 4; ++i)
            glNamedFramebufferTexture(fbo_.id(), GLenum(GL_COLOR_ATTACHMENT0 + i), 0, 0);
    }
    fbo_.attachDepth(depth_);
    fbo_.finalize(colorCount);
    const float far[4] = {1e30f, 0, 0, 0}, zero[4] = {0, 0, 0, 0}, one = 1.0f;
    glClearBufferfv(GL_COLOR, 0, far);
    for (int i = 1; i < colorCount; ++i) glClearBufferfv(GL_COLOR, i, zero);
    glClearBufferfv(GL_DEPTH, 0, &one);
}

void ShadowPass::renderLayer(FrameContext& ctx, int light, int layer, Occluders which, bool rsm) {
    const int atlasLayer = ctx.plan.lights[size_t(light)].firstLayer + layer;
    beginLayer(which == Occluders::Real ? distanceReal_ : distance_, atlasLayer, rsm);
    drawOccluders(ctx, light, layer, which, rsm);
}

// The RSM layer alone at rsmSize (its own raster and depth buffer; the occluder distance is not
// written: colour attachment 0 is left out of the draw buffers).
void ShadowPass::renderRsmLayer(FrameContext& ctx, int light, int layer) {
    const int atlasLayer = ctx.plan.lights[size_t(light)].firstLayer + layer;
    rsmFbo_.attachColorLayer(1, rsmFlux_, atlasLayer);
    rsmFbo_.attachColorLayer(2, rsmNormal_, atlasLayer);
    rsmFbo_.attachColorLayer(3, rsmPosition_, atlasLayer);
    rsmFbo_.attachDepth(separateRsm() ? rsmDepth_ : depth_);  // a focused light's, at mapSize
    rsmFbo_.finalize(4);  // checks completeness; attachment 0 stays empty
    const GLenum bufs[4] = {GL_NONE, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2,
                            GL_COLOR_ATTACHMENT3};
    glNamedFramebufferDrawBuffers(rsmFbo_.id(), 4, bufs);
    rsmFbo_.bind();
    glViewport(0, 0, rsmSize_, rsmSize_);
    const float zero[4] = {0, 0, 0, 0}, one = 1.0f;
    for (int i = 1; i < 4; ++i) glClearBufferfv(GL_COLOR, i, zero);
    glClearBufferfv(GL_DEPTH, 0, &one);
    drawOccluders(ctx, light, layer, Occluders::All, true);
    fbo_.bind();
    glViewport(0, 0, allocatedSize_, allocatedSize_);
}

// Focused map k of a light: its group of virtual draws through the frustum fitted to them (the
// occluder distance only).
void ShadowPass::renderFocusLayer(FrameContext& ctx, int light, int focusMap) {
    const LightPlan& lp = ctx.plan.lights[size_t(light)];
    beginLayer(distance_, lp.firstFocusLayer + focusMap, false);
    const glm::mat4& vp = ctx.lightBlock.lights[light].focusViewProj[focusMap];
    glUniformMatrix4fv(locViewProj_, 1, GL_FALSE, &vp[0][0]);
    glUniform1i(locLight_, light);
    glUniform1i(locGlassLayer_, -1);
    for (int d : lp.focusDraws[size_t(focusMap)])
        draw_.draw(ctx.scene, ctx.scene.draws()[size_t(d)]);
}

void ShadowPass::drawOccluders(FrameContext& ctx, int light, int layer, Occluders which, bool rsm) {
    const LightPlan& lp = ctx.plan.lights[size_t(light)];
    const int atlasLayer = lp.firstLayer + layer;
    const glm::mat4& vp = ctx.lightBlock.lights[light].viewProj[layer];
    glUniformMatrix4fv(locViewProj_, 1, GL_FALSE, &vp[0][0]);
    glUniform1i(locLight_, light);
    glUniform1i(locGlassLayer_, rsm && lp.hasGlassLayer() ? atlasLayer : -1);
    // The glass layer has the shadow map's texels; the RSM raster may be coarser or finer.
    glUniform1f(locGlassScale_, float(allocatedSize_) / float(rsm ? rsmSize_ : allocatedSize_));
    glBindTextureUnit(kUnitShadowGlassLayer, glass_.id());
    if (which == Occluders::Unfocused) {
        for (int i : lp.unfocusedDraws) draw_.draw(ctx.scene, ctx.scene.draws()[size_t(i)]);
        return;
    }
    for (const DrawItem& d : ctx.scene.draws()) {
        if (which == Occluders::Real && d.origin != Origin::Real) continue;
        if (lp.glassTransmits && d.transmissive) continue;  // in the glass layer instead
        if (lp.translucentTransmits && d.translucent) continue;
        draw_.draw(ctx.scene, d);
    }
}

// The translucent draw's medium for shadow_glass.frag (translucent = 0 for glass).
void ShadowPass::setMediumUniforms(const DrawItem& d, const GpuMedium* medium) {
    const GLuint p = glassProgram_.id();
    glProgramUniform1i(p, locTranslucent_, medium ? 1 : 0);
    if (!medium) return;
    glProgramUniform1f(p, locExtinction_, medium->extinction);
    const glm::vec3 k = translucency::shadowExtinctionScale(medium->albedo);
    glProgramUniform3fv(p, locShadowScale_, 1, &k[0]);
    glProgramUniform1f(p, locIor_, medium->ior);
    glProgramUniform1i(p, locHasDensity_, medium->hasDensity ? 1 : 0);
    const glm::mat4 localFromWorld = glm::inverse(d.model);
    glProgramUniformMatrix4fv(p, locLocalFromWorld_, 1, GL_FALSE, &localFromWorld[0][0]);
    glProgramUniform3fv(p, locDensityMin_, 1, &medium->boundsMin[0]);
    glProgramUniform3fv(p, locDensityMax_, 1, &medium->boundsMax[0]);
    const glm::vec3 cells(medium->gridSize);
    glProgramUniform3fv(p, locDensityCells_, 1, &cells[0]);
    if (medium->hasDensity) glBindTextureUnit(kUnitShadowDensity, medium->density.id());
}

void ShadowPass::renderGlassLayer(FrameContext& ctx, int light, int layer, bool realOnly) {
    const LightPlan& lp = ctx.plan.lights[size_t(light)];
    const int atlasLayer = lp.firstLayer + layer;
    glassFbo_.attachColorLayer(0, realOnly ? glassReal_ : glass_, atlasLayer);
    glassFbo_.finalize(1);
    glassFbo_.bind();
    const float clear[4] = {0.0f, 0.0f, 0.0f, 1e30f};
    glClearBufferfv(GL_COLOR, 0, clear);
    glassProgram_.use();
    const glm::mat4& vp = ctx.lightBlock.lights[light].viewProj[layer];
    glUniformMatrix4fv(locGlassViewProj_, 1, GL_FALSE, &vp[0][0]);
    glUniform1i(locGlassLight_, light);
    // Every crossing counts (no depth test): rgb adds the ln(transmittance) terms, alpha keeps
    // the nearest glass distance.
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendEquationSeparate(GL_FUNC_ADD, GL_MIN);
    glBlendFunc(GL_ONE, GL_ONE);
    for (const DrawItem& d : ctx.scene.draws()) {
        if (realOnly && d.origin != Origin::Real) continue;
        const GpuMedium* medium = d.translucent ? ctx.scene.medium(d.material) : nullptr;
        if (!(lp.glassTransmits && d.transmissive) && !(lp.translucentTransmits && medium))
            continue;
        setMediumUniforms(d, medium);
        glassDraw_.draw(ctx.scene, d);
    }
    glDisable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glEnable(GL_DEPTH_TEST);
    fbo_.bind();
    program_.use();
}

void ShadowPass::execute(FrameContext& ctx, PassResources& res) {
    fbo_.bind();
    glViewport(0, 0, allocatedSize_, allocatedSize_);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    program_.use();
    ctx.bindFrameBlocks();
    ctx.scene.bindGeometry();
    if (ctx.plan.glassShadows) {  // layers of lights without glass: no glass anywhere
        const float noGlass[4] = {0.0f, 0.0f, 0.0f, 1e30f};
        glClearTexImage(glass_.id(), 0, GL_RGBA, GL_FLOAT, noGlass);
        if (ctx.plan.needRealOnlyGlass)
            glClearTexImage(glassReal_.id(), 0, GL_RGBA, GL_FLOAT, noGlass);
    }
    for (size_t i = 0; i < ctx.plan.lights.size(); ++i) {
        const LightPlan& lp = ctx.plan.lights[i];
        if (!lp.castsShadow) continue;
        for (int layer = 0; layer < lp.layers; ++layer) {
            if (lp.hasGlassLayer()) {
                renderGlassLayer(ctx, int(i), layer, false);
                if (lp.needsRealOnlyGlass) renderGlassLayer(ctx, int(i), layer, true);
            }
            const bool rsm = ctx.plan.needVpls && lp.hasRsm;
            if (lp.focusedVirtual()) {  // the RSM sees every surface; the distance maps split
                if (rsm) renderRsmLayer(ctx, int(i), layer);
                renderLayer(ctx, int(i), layer, Occluders::Real, false);
                if (!lp.unfocusedDraws.empty())
                    renderLayer(ctx, int(i), layer, Occluders::Unfocused, false);
                continue;
            }
            renderLayer(ctx, int(i), layer, Occluders::All, rsm && !separateRsm());
            if (rsm && separateRsm()) renderRsmLayer(ctx, int(i), layer);
            if (lp.needsRealOnlyMap) renderLayer(ctx, int(i), layer, Occluders::Real, false);
        }
        for (size_t k = 0; k < lp.focusDraws.size(); ++k) renderFocusLayer(ctx, int(i), int(k));
    }
    glDisable(GL_DEPTH_TEST);
    res.publish(kShadowMaps, distance_);
    res.publish(kShadowMapsReal, ctx.plan.needRealOnlyShadows ? distanceReal_ : distance_);
    if (ctx.plan.glassShadows) {
        res.publish(kShadowGlass, glass_);
        res.publish(kShadowGlassReal, ctx.plan.needRealOnlyGlass ? glassReal_ : glass_);
    }
    if (ctx.plan.needVpls) {
        res.publish(kRsmFlux, rsmFlux_);
        res.publish(kRsmNormal, rsmNormal_);
        res.publish(kRsmPosition, rsmPosition_);
    }
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeShadowPass(const PassInit&) {
    return std::make_unique<ShadowPass>();
}

}  // namespace mirage::render
