#include "render/passes/motionblur/MotionBlurPass.h"

#include <cmath>

#include <fmt/format.h>

#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/passes/composite/CompositePass.h"
#include "render/passes/gbuffer/GBufferPass.h"

namespace mirage::render {
namespace {
// A real pixel whose composite differs from its footage by less than this (camera linear units,
// any channel) counts as unchanged: a tenth of an 8-bit step in the darkest codes.
constexpr float kChangeEpsilon = 1e-4f;
}  // namespace

void MotionBlurPass::setup(PassBuilder& b) const {
    b.read(kGBufferPosition);
    b.read(kCompositeFootage);
    b.create(kMotionVelocity, {GL_RGBA16F, SizeRule::Camera, Storage::PassOwned});
    CompositeVersion::declare(b);
}

std::optional<double> MotionBlurPass::exposureScale(const FrameContext& ctx, std::string* why) {
    const MotionBlurOptions& o = ctx.options.motionBlur;
    auto refuse = [&](std::string reason) -> std::optional<double> {
        if (why) *why = std::move(reason);
        return std::nullopt;
    };
    if (!o.enabled()) return refuse("motion blur off: no shutter time");
    if (!ctx.previous) return refuse("first frame: no previous pose");
    if (!std::isfinite(ctx.time) || !std::isfinite(ctx.previous->time))
        return refuse("frame time unknown");
    const double dt = ctx.time - ctx.previous->time;
    if (!(dt > 0.0)) return refuse(fmt::format("frame time does not advance ({:.4g} s)", dt));
    if (dt > o.maxFrameGap)
        return refuse(fmt::format("{:.3g} s since the previous frame (more than {:.3g} s)", dt,
                                  o.maxFrameGap));
    if (why)
        *why =
            fmt::format("shutter {:.4g} s over a frame interval of {:.4g} s", o.shutterSeconds, dt);
    return o.shutterSeconds / dt;
}

PassDecision MotionBlurPass::decide(const FrameContext& ctx) const {
    std::string why;
    const bool run = exposureScale(ctx, &why).has_value();
    return {run, why};
}

void MotionBlurPass::resize(const FrameContext& ctx) {
    const CameraProjection& p = ctx.projection;
    const int w = p.camera.width, h = p.camera.height;
    const int k = ctx.options.motionBlur.tileSize;
    if (w == width_ && h == height_ && k == tileSize_) return;
    width_ = w;
    height_ = h;
    tileSize_ = k;
    const bool identity = CompositePass::isIdentityRemap(p);
    velocityProgram_ =
        fullscreenProgram("motion velocity", "passes/motionblur/motion_velocity.frag",
                          identity ? "#define MIRAGE_IDENTITY_REMAP 1\n" : "");
    tilesProgram_ = fullscreenProgram("motion tiles", "passes/motionblur/motion_tiles.frag");
    neighboursProgram_ =
        fullscreenProgram("motion neighbours", "passes/motionblur/motion_neighbours.frag");
    gatherProgram_ = fullscreenProgram("motion gather", "passes/motionblur/motion_gather.frag");
    locPreviousViewProj_ = velocityProgram_.uniformLocation("previousViewProj");
    locClipToPrevious_ = velocityProgram_.uniformLocation("clipToPrevious");
    locExposureScale_ = velocityProgram_.uniformLocation("exposureScale");
    locMaxHalfLength_ = velocityProgram_.uniformLocation("maxHalfLength");
    locTileSize_ = tilesProgram_.uniformLocation("tileSize");
    locChangeEpsilon_ = tilesProgram_.uniformLocation("changeEpsilon");
    locGatherTileSize_ = gatherProgram_.uniformLocation("tileSize");
    locSamples_ = gatherProgram_.uniformLocation("samples");
    locSoftDepth_ = gatherProgram_.uniformLocation("softDepthExtent");

    remap_ = gl::Texture::create2D("motion blur lens remap", w, h, GL_RG32F);
    remap_.setFilter(GL_NEAREST, GL_NEAREST);
    remap_.upload(GL_RG, GL_FLOAT, p.remap.data());
    velocity_ = gl::Texture::create2D("motion velocity", w, h, GL_RGBA16F);
    velocity_.setFilter(GL_NEAREST, GL_NEAREST);
    const int tw = (w + k - 1) / k, th = (h + k - 1) / k;
    tiles_ = gl::Texture::create2D("motion tile max", tw, th, GL_RGBA16F);
    neighbours_ = gl::Texture::create2D("motion neighbour max", tw, th, GL_RGBA16F);
    velocityFbo_ = gl::Framebuffer("motion velocity fbo");
    velocityFbo_.attachColor(0, velocity_);
    velocityFbo_.finalize(1);
    tilesFbo_ = gl::Framebuffer("motion tiles fbo");
    tilesFbo_.attachColor(0, tiles_);
    tilesFbo_.finalize(1);
    neighboursFbo_ = gl::Framebuffer("motion neighbours fbo");
    neighboursFbo_.attachColor(0, neighbours_);
    neighboursFbo_.finalize(1);
    output_.resize(w, h);
}

void MotionBlurPass::execute(FrameContext& ctx, PassResources& res) {
    const MotionBlurOptions& o = ctx.options.motionBlur;
    const double scale = exposureScale(ctx, nullptr).value_or(0.0);
    const glm::mat4 clipToPrevious = ctx.previous->viewProj * glm::inverse(ctx.frame.viewProj);
    const int tw = tiles_.width(), th = tiles_.height();

    velocityFbo_.bind();
    ctx.beginFullscreen(velocityProgram_, width_, height_);
    glUniformMatrix4fv(locPreviousViewProj_, 1, GL_FALSE, &ctx.previous->viewProj[0][0]);
    glUniformMatrix4fv(locClipToPrevious_, 1, GL_FALSE, &clipToPrevious[0][0]);
    glUniform1f(locExposureScale_, float(scale));
    glUniform1f(locMaxHalfLength_, float(o.tileSize));
    glBindTextureUnit(kUnitMotionPosition, res.texture(kGBufferPosition).id());
    glBindTextureUnit(kUnitMotionRemap, remap_.id());
    ctx.drawFullscreenTriangle();

    const gl::Texture& composite = res.texture(kComposite);
    const gl::Texture& footage = res.texture(kCompositeFootage);
    tilesFbo_.bind();
    ctx.beginFullscreen(tilesProgram_, tw, th);
    glUniform1i(locTileSize_, o.tileSize);
    glUniform1f(locChangeEpsilon_, kChangeEpsilon);
    glBindTextureUnit(kUnitMotionVelocity, velocity_.id());
    glBindTextureUnit(kUnitMotionComposite, composite.id());
    glBindTextureUnit(kUnitMotionFootage, footage.id());
    ctx.drawFullscreenTriangle();

    neighboursFbo_.bind();
    ctx.beginFullscreen(neighboursProgram_, tw, th);
    glBindTextureUnit(kUnitMotionTiles, tiles_.id());
    ctx.drawFullscreenTriangle();

    output_.bind();
    glEnable(GL_FRAMEBUFFER_SRGB);
    ctx.beginFullscreen(gatherProgram_, width_, height_);
    glUniform1i(locGatherTileSize_, o.tileSize);
    glUniform1i(locSamples_, o.samples);
    glUniform1f(locSoftDepth_, o.softDepthExtent);
    glBindTextureUnit(kUnitMotionVelocity, velocity_.id());
    glBindTextureUnit(kUnitMotionTiles, neighbours_.id());
    glBindTextureUnit(kUnitMotionComposite, composite.id());
    glBindTextureUnit(kUnitMotionFootage, footage.id());
    ctx.drawFullscreenTriangle();
    glDisable(GL_FRAMEBUFFER_SRGB);

    res.publish(kMotionVelocity, velocity_);
    output_.publish(res);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeMotionBlurPass(const PassInit&) {
    return std::make_unique<MotionBlurPass>();
}

}  // namespace mirage::render
