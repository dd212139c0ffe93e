#pragma once
// Geometry-aware + temporal filter of the VPL light: the K x K filter, de-interleaving and
// temporal smoothing at gather resolution (filter.frag; its output is the next frame's history,
// so two gather-size buffers ping-pong), and the same light packed per gather pixel
// (GatherLight) for the joint bilateral upsampling, which the direct-light pass does while it
// sums direct and indirect light into LRv / LR (passes/direct/gi_upsample.glsl): one canvas-size
// pass fewer.
#include "render/RenderPass.h"
#include "render/TemporalHistory.h"

namespace mirage::render {

// Filtered indirect light at gather resolution, a = camera distance (m); kept as the next
// frame's temporal history (persistent).
inline constexpr Resource kGiHistoryRv{"GiHistoryRv"};
inline constexpr Resource kGiHistoryR{"GiHistoryR"};
// The filtered indirect light packed per gather pixel for the upsample: L_rv, L_r as halves,
// camera-frame depth as a half, 8-bit oct normal (RGBA32UI).
inline constexpr Resource kGatherLight{"GatherLight"};

class GiFilterPass final : public RenderPass {
public:
    // interleave: RendererOptions::indirect.interleave (K), compiled into the filter shader.
    explicit GiFilterPass(int interleave);
    const char* name() const override { return "gifilter"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    gl::Program filter_;  // K x K geometry-aware filter + temporal, gather resolution
    // Filtered indirect light at gather resolution, rgb + camera distance (m) in a; [current_]
    // is written this frame and read as history by the next (history_ says which).
    gl::Texture lowRv_[2], lowR_[2];
    // The filtered light packed for the upsample (filter.frag): L_rv, L_r, depth, normal.
    gl::Texture gatherLight_;
    gl::Framebuffer lowFbo_[2];
    TemporalHistory history_;
};

}  // namespace mirage::render
