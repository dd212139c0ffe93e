#include "render/passes/aa/AntialiasPass.h"

#include <fmt/format.h>

#include "render/FrameGraph.h"
#include "render/FrameImports.h"
#include "render/PassRegistry.h"
#include "render/passes/composite/CompositePass.h"
#include "render/passes/composite/CompositeVersion.h"

namespace mirage::render {

AntialiasPass::AntialiasPass()
    : program_(fullscreenProgram("antialias", "passes/aa/antialias.frag")),
      bilinear_("antialias bilinear", GL_LINEAR, GL_LINEAR, GL_CLAMP_TO_EDGE) {
    locEdgeThreshold_ = program_.uniformLocation("edgeThreshold");
    locEdgeThresholdMin_ = program_.uniformLocation("edgeThresholdMin");
    locSubpixel_ = program_.uniformLocation("subpixel");
    locChangeEpsilon_ = program_.uniformLocation("changeEpsilon");
    locSearchSteps_ = program_.uniformLocation("searchSteps");
}

void AntialiasPass::setup(PassBuilder& b) const {
    b.read(kCameraImage);
    CompositeVersion::declare(b);
}

PassDecision AntialiasPass::decide(const FrameContext& ctx) const {
    if (!ctx.options.aa.enabled) return {false, "anti-aliasing off"};
    if (!ctx.options.composite.showVirtual)
        return {false, "virtual objects hidden: the composite is the footage"};
    return {true, fmt::format("morphological, on the edges of what the renderer added ({} search "
                              "steps)",
                              ctx.options.aa.searchSteps)};
}

void AntialiasPass::resize(const FrameContext& ctx) {
    const int w = ctx.projection.camera.width, h = ctx.projection.camera.height;
    output_.resize(w, h);
}

void AntialiasPass::execute(FrameContext& ctx, PassResources& res) {
    const AntialiasOptions& o = ctx.options.aa;
    output_.bind();
    glEnable(GL_FRAMEBUFFER_SRGB);
    ctx.beginFullscreen(program_, ctx.projection.camera.width, ctx.projection.camera.height);
    glUniform1f(locEdgeThreshold_, o.edgeThreshold);
    glUniform1f(locEdgeThresholdMin_, o.edgeThresholdMin);
    glUniform1f(locSubpixel_, o.subpixel);
    glUniform1f(locChangeEpsilon_, o.changeEpsilon);
    glUniform1i(locSearchSteps_, o.searchSteps);
    glBindTextureUnit(kUnitAntialiasComposite, res.texture(kComposite).id());
    glBindTextureUnit(kUnitAntialiasCamera, res.texture(kCameraImage).id());
    glBindSampler(kUnitAntialiasComposite, bilinear_.id());
    glBindSampler(kUnitAntialiasCamera, bilinear_.id());
    ctx.drawFullscreenTriangle();
    glBindSampler(kUnitAntialiasComposite, 0);
    glBindSampler(kUnitAntialiasCamera, 0);
    glDisable(GL_FRAMEBUFFER_SRGB);
    output_.publish(res);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeAntialiasPass(const PassInit&) {
    return std::make_unique<AntialiasPass>();
}

}  // namespace mirage::render
