#include "render/passes/gifilter/GiFilterPass.h"

#include <algorithm>
#include <string>

#include "render/FrameGraph.h"

namespace mirage::render {
namespace {

// R^T K^-1 on the canvas: the world direction, at camera-frame depth 1, of canvas pixel (x, y)
// with pixel centres at integers (x / z = (x - cx) / fx, as the projection matrix maps it).
glm::mat3 rayFromCanvasPixel(const FrameContext& ctx) {
    const CameraProjection& p = ctx.projection;
    glm::mat3 kInv(1.0f);  // column-major: [column][row]
    kInv[0][0] = float(1.0 / p.camera.fx);
    kInv[1][1] = float(1.0 / p.camera.fy);
    kInv[2][0] = float(-p.canvasCx / p.camera.fx);
    kInv[2][1] = float(-p.canvasCy / p.camera.fy);
    return glm::transpose(glm::mat3(ctx.frame.viewMatrix)) * kInv;
}

}  // namespace

GiFilterPass::GiFilterPass(int interleave)
    : filter_(fullscreenProgram(
          "gi filter", "passes/gifilter/filter.frag",
          "#define MIRAGE_INTERLEAVE " + std::to_string(std::max(1, interleave)))),
      upsample_(fullscreenProgram("gi upsample", "passes/gifilter/upsample.frag")) {}

void GiFilterPass::setup(PassBuilder& b) const {
    b.read(Resource::GBufferPosition);
    b.read(Resource::GBufferNormal);
    b.read(Resource::IndirectRv);
    b.read(Resource::IndirectR);
    b.read(Resource::DirectRv);
    b.read(Resource::DirectR);
    b.readOptional(Resource::SpecularMask);  // none: no mirror or glass object in view
    // This frame's filtered indirect light, read back by the next frame as temporal history.
    b.write(Resource::GiHistoryRv, GL_RGBA32F, SizeRule::Gather, true);
    b.write(Resource::GiHistoryR, GL_RGBA32F, SizeRule::Gather, true);
    b.write(Resource::LRv, GL_RGBA16F, SizeRule::Canvas);
    b.write(Resource::LR, GL_RGBA16F, SizeRule::Canvas);
}

PassDecision GiFilterPass::decide(const FrameContext& ctx) const {
    return {true, std::string("geometry-aware ") + std::to_string(ctx.options.interleave) + "x" +
                      std::to_string(ctx.options.interleave) + ", " +
                      history_.note(ctx, ctx.options.temporalBlend)};
}

void GiFilterPass::resize(const FrameContext& ctx) {
    const int w = ctx.canvasWidth(), h = ctx.canvasHeight(), s = ctx.gatherScale();
    // Runs before every frame: reallocating would also throw the temporal history away.
    const int lowW = (w + s - 1) / s, lowH = (h + s - 1) / s;
    if (rv_.width() == w && rv_.height() == h && lowRv_[0].width() == lowW &&
        lowRv_[0].height() == lowH)
        return;
    gatherLight_ = gl::Texture::create2D("indirect upsample light", lowW, lowH, GL_RGBA32UI);
    gatherLight_.setFilter(GL_NEAREST, GL_NEAREST);
    for (int i = 0; i < 2; ++i) {
        // 32-bit: alpha holds the camera distance the history test compares (temporal.glsl).
        lowRv_[i] = gl::Texture::create2D("indirect L_rv filtered", lowW, lowH, GL_RGBA32F);
        lowR_[i] = gl::Texture::create2D("indirect L_r filtered", lowW, lowH, GL_RGBA32F);
        // Linear: the history is read at reprojected, fractional positions.
        lowRv_[i].setFilter(GL_LINEAR, GL_LINEAR);
        lowR_[i].setFilter(GL_LINEAR, GL_LINEAR);
        lowFbo_[i] = gl::Framebuffer("gi filter fbo");
        lowFbo_[i].attachColor(0, lowRv_[i]);
        lowFbo_[i].attachColor(1, lowR_[i]);
        lowFbo_[i].attachColor(2, gatherLight_);
        lowFbo_[i].finalize(3);
    }
    history_.drop();  // new buffers hold no history
    rv_ = gl::Texture::create2D("L_rv", w, h, GL_RGBA16F);
    r_ = gl::Texture::create2D("L_r", w, h, GL_RGBA16F);
    fbo_ = gl::Framebuffer("gi upsample fbo");
    fbo_.attachColor(0, rv_);
    fbo_.attachColor(1, r_);
    fbo_.finalize(2);
    attachedMask_ = 0;
}

void GiFilterPass::execute(FrameContext& ctx, PassResources& res) {
    const int write = history_.writeSlot(), read = history_.readSlot();
    lowFbo_[write].bind();
    ctx.beginFullscreen(filter_, lowRv_[write].width(), lowRv_[write].height());
    glUniform1i(filter_.uniformLocation("scale"), ctx.gatherScale());
    glUniform1f(filter_.uniformLocation("historyWeight"),
                history_.usable(ctx, ctx.options.temporalBlend) ? ctx.options.temporalBlend : 0.0f);
    const GLuint position = res.texture(Resource::GBufferPosition).id();
    const GLuint normal = res.texture(Resource::GBufferNormal).id();
    glBindTextureUnit(kUnitFilterPosition, position);
    glBindTextureUnit(kUnitFilterNormal, normal);
    glBindTextureUnit(kUnitFilterIndirectRv, res.texture(Resource::IndirectRv).id());
    glBindTextureUnit(kUnitFilterIndirectR, res.texture(Resource::IndirectR).id());
    glBindTextureUnit(kUnitFilterHistoryRv, lowRv_[read].id());
    glBindTextureUnit(kUnitFilterHistoryR, lowR_[read].id());
    ctx.drawFullscreenTriangle();

    const gl::Texture* mask =
        res.has(Resource::SpecularMask) && !ctx.options.diffuseOnSpecularPixels
            ? &res.texture(Resource::SpecularMask)
            : nullptr;
    if (mask && mask->id() != attachedMask_) {  // reallocated only on a resize
        fbo_.attachDepth(*mask);
        fbo_.finalize(2);
        attachedMask_ = mask->id();
    }
    fbo_.bind();
    ctx.beginFullscreen(upsample_, ctx.canvasWidth(), ctx.canvasHeight());
    glUniform1i(upsample_.uniformLocation("scale"), ctx.gatherScale());
    glBindTextureUnit(kUnitUpsamplePosition, position);
    glBindTextureUnit(kUnitUpsampleNormal, normal);
    glUniformMatrix3fv(upsample_.uniformLocation("rayFromPixel"), 1, GL_FALSE,
                       &rayFromCanvasPixel(ctx)[0][0]);
    glBindTextureUnit(kUnitUpsampleGatherLight, gatherLight_.id());
    glBindTextureUnit(kUnitUpsampleDirectRv, res.texture(Resource::DirectRv).id());
    glBindTextureUnit(kUnitUpsampleDirectR, res.texture(Resource::DirectR).id());
    // Mirror and glass pixels take their light from the specular passes: not upsampled here.
    if (mask)
        ctx.drawFullscreenTriangleOutsideSpecular(0, 2);
    else
        ctx.drawFullscreenTriangle();
    history_.written(ctx);
    res.publish(Resource::GiHistoryRv, lowRv_[write]);
    res.publish(Resource::GiHistoryR, lowR_[write]);
    res.publish(Resource::LRv, rv_);
    res.publish(Resource::LR, r_);
}

}  // namespace mirage::render
