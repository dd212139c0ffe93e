#pragma once
// Direct + environment + emitted light for every G-buffer pixel, and the GI solutions LRv / LR:
// in frames with VPL light, the filtered indirect light (gifilter's GatherLight) is upsampled
// to the pixel and added in the same pass (gi_upsample.glsl); otherwise LRv / LR are the direct
// light alone and are published as DirectRv / DirectR too. With
// RendererOptions::direct.keepDirectLight the direct light alone is also written to DirectRv /
// DirectR in VPL frames (two more targets; tests and buffer views).
#include <map>
#include <tuple>

#include "render/RenderPass.h"

namespace mirage::render {

// Direct + environment + emission (canvas size): LRv itself in frames without VPL light, else
// written apart only with RendererOptions::direct.keepDirectLight.
inline constexpr Resource kDirectRv{"DirectRv"};
inline constexpr Resource kDirectR{"DirectR"};
// The two GI solutions: direct + filtered, upsampled indirect (canvas size); LRv.a = the pixel's
// origin (ORIGIN_*; 0 on the specular pixels it skips).
inline constexpr Resource kLRv{"LRv"};
inline constexpr Resource kLR{"LR"};

class DirectLightPass final : public RenderPass {
public:
    explicit DirectLightPass(const GpuScene& scene);
    const char* name() const override { return "direct"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    // The shader variant for (glass shadows, indirect light added, direct light kept apart),
    // compiled on first use: llvmpipe pays for a branch's texture reads even when no pixel takes
    // it, so each combination is its own program.
    gl::Program& program(bool glass, bool indirect, bool keepDirect, bool highlight = false);
    void drawRoughHighlight(FrameContext& ctx, gl::Program& prog, bool masked);

    std::string sceneDefines_, sceneDefinesNoGlass_;
    std::map<std::tuple<bool, bool, bool, bool>, gl::Program> programs_;
    gl::Texture rv_, r_, directRv_, directR_;
    gl::Framebuffer fbo_, keepFbo_;                   // LRv, LR; and + DirectRv, DirectR
    GLuint attachedMask_ = 0, keepAttachedMask_ = 0;  // SpecularMask attached as their depth
};

}  // namespace mirage::render
