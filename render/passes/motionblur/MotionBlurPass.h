#pragma once
// Motion blur of what the renderer adds to the footage (docs/camera-matching.md, "Motion blur"):
// the camera blurs the footage while its shutter is open; the virtual objects and the renderer's
// changes to real surfaces (shadows, reflected light) must be blurred the same way, or they look
// pasted onto a blurred picture.
//
// After the composite, in four full-screen draws:
//  1. velocity (motion_velocity.frag): per camera pixel, the screen motion over the exposure of
//     the surface it shows, from the previous frame's camera to this one's
//     (FrameContext::previous), scaled by shutter / frame interval; published as MotionVelocity;
//  2. tile maxima and 3. their 3 x 3 neighbourhood maxima (motion_tiles.frag,
//     motion_neighbours.frag), with a flag for tiles the renderer changed;
//  4. the gather (motion_gather.frag): McGuire et al. 2012's reconstruction filter on the
//     composite minus its footage, so the footage is never blurred twice.
// It writes new versions of Composite and CompositeSrgb. It runs only with a shutter time
// (RendererOptions::motionBlur.shutterSeconds > 0) and a previous frame at most maxFrameGap
// seconds before this one, both with known times; otherwise the composite stays as it is and the
// report says why.
#include <optional>
#include <string>

#include "render/RenderPass.h"
#include "render/passes/composite/CompositeVersion.h"

namespace mirage::render {

// Camera size, RGBA16F: rg = half the screen motion over the exposure (camera pixels, clamped to
// motionBlur.tileSize), b = depth along the camera axis (metres).
inline constexpr Resource kMotionVelocity{"MotionVelocity"};

class MotionBlurPass final : public RenderPass {
public:
    MotionBlurPass() = default;  // the programs are built by resize(), for the camera
    const char* name() const override { return "motionblur"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

    // Shutter / (this frame's time - the previous one's): the exposure's share of the motion
    // since the previous frame; nullopt with the reason when the frame cannot be blurred.
    static std::optional<double> exposureScale(const FrameContext& ctx, std::string* why);

private:
    gl::Program velocityProgram_, tilesProgram_, neighboursProgram_, gatherProgram_;
    GLint locPreviousViewProj_ = -1, locClipToPrevious_ = -1, locExposureScale_ = -1,
          locMaxHalfLength_ = -1;
    GLint locTileSize_ = -1, locChangeEpsilon_ = -1;
    GLint locGatherTileSize_ = -1, locSamples_ = -1, locSoftDepth_ = -1;
    gl::Texture remap_, velocity_, tiles_, neighbours_;
    gl::Framebuffer velocityFbo_, tilesFbo_, neighboursFbo_;
    CompositeVersion output_{"motion blurred composite"};
    int width_ = 0, height_ = 0, tileSize_ = 0;
};

}  // namespace mirage::render
