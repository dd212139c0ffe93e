#pragma once
// The environment light of the frame (docs/environment.md): the equirectangular map every
// environment lookup samples (L_env of rays that leave the modelled scene) and its SH9 for the
// diffuse environment light. Two sources:
//  - static: the scene's map (SceneEnvironmentMap, published as it is) and the SH9 the CPU
//    projected when the scene was uploaded; built on the first frame, then reused;
//  - live: the environment camera's newest frame (EnvironmentCamera, Renderer::updateEnvironment)
//    reprojected onto the map through its calibration and pose (fisheye_to_equirect.frag, the
//    unseen part filled by mirroring through the camera's image plane), mip-mapped, and projected
//    to SH9 on the GPU (environment_sh.comp); when lights found in the frame are placed as lights
//    of their own (RendererOptions::environment.lights), the SH9 is that of the map without them,
//    computed on the CPU (render/EnvironmentLights.h), while the map keeps them (what rays see).
//    Runs only when a new frame arrived (upToDate); every other frame the graph republishes the
//    last map and SH.
#include <cstdint>

#include "render/RenderPass.h"

namespace mirage::render {

// The environment light: the map every environment lookup uses (equirectangular RGBA16F, rgb
// linear radiance, a = 1 where the camera saw the direction, 0 where the unseen part was filled
// in; mip-mapped when live) and its SH9 (EnvironmentBlock). Persistent.
inline constexpr Resource kEnvironmentMap{"EnvironmentMap"};
inline constexpr Resource kEnvironmentLight{"EnvironmentLight"};

class EnvironmentPass final : public RenderPass {
public:
    EnvironmentPass();
    const char* name() const override { return "environment"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    bool upToDate(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    void executeLive(FrameContext& ctx, PassResources& res);
    gl::Program toEquirect_, sh_;
    gl::Texture map_;  // live map: environmentMapWidth x width / 2, full mip chain
    gl::Framebuffer fbo_;
    gl::Buffer light_;  // GpuEnvironment
    uint64_t doneGeneration_ = UINT64_MAX;
    // Uniform locations of fisheye_to_equirect.frag / environment_sh.comp.
    GLint uCameraFromWorld_ = -1, uFocal_ = -1, uDistortion_ = -1, uK3_ = -1, uKb_ = -1,
          uImageSize_ = -1, uMaxTheta_ = -1, uGain_ = -1, uLevel_ = -1;
};

}  // namespace mirage::render
