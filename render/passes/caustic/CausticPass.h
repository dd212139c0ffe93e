#pragma once
// The caustic buffer and its light (Knecht 2013 Sec. 4.2.1, 5.2; docs/caustics.md): the
// photons of the photon G-buffers splatted as quads in camera space by a compute shader (integer
// atomics into a fixed-point irradiance buffer, depth-rejected against the G-buffer), then
// resolved into the caustic radiance the receivers reflect, routed into L_rv and L_r by Eqs.
// 12-14. The composite adds CausticRv / CausticR to the GI solutions. The irradiance is
// smoothed over time before the routing (RendererOptions::caustic.temporal): two canvas-size
// buffers ping-pong as this frame's result and the next frame's history. Only the tiles the
// caustic can reach are resolved (the tiles the photons reached and those where last frame's
// history can pass, CausticTiles.h), drawn as quads; the rest are cleared to 0.
#include "render/RenderPass.h"
#include "render/TemporalHistory.h"
#include "render/passes/caustic/CausticTiles.h"

namespace mirage::render {

// Caustic radiance reflected by the receiver towards the camera (Eq. 12) and the same for L_r
// (light, specular object and receiver real: Eqs. 13-14).
inline constexpr Resource kCausticRv{"CausticRv"};
inline constexpr Resource kCausticR{"CausticR"};
// The caustic irradiance (rgb W/m^2, before the receiver's albedo) for L_rv / L_r after temporal
// smoothing, a = camera distance (m) of the receiver (0: none): the next frame's history
// (persistent, canvas size).
inline constexpr Resource kCausticHistoryRv{"CausticHistoryRv"};
inline constexpr Resource kCausticHistoryR{"CausticHistoryR"};

class CausticPass final : public RenderPass {
public:
    CausticPass();
    const char* name() const override { return "caustic"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    // This frame takes last frame's caustic instead of splatting (CausticOptions::refreshInterval
    // and reuseMaxNewView).
    bool reusesHistory(const FrameContext& ctx) const;
    // The refresh interval alone would reuse the history this frame.
    bool intervalAllowsReuse(const FrameContext& ctx) const;
    // The share of this frame's view that last frame's did not show (CausticTiles.h).
    float newViewShare(const FrameContext& ctx) const;
    CausticReprojection cameras(const FrameContext& ctx) const;
    // Last frame's history tiles (only while its history is usable: the textures exist).
    const CausticHistoryTiles& lastHistory(const FrameContext& ctx) const;
    void splat(FrameContext& ctx, PassResources& res, float fixedScale);
    void resolve(FrameContext& ctx, PassResources& res, float invFixedScale, bool reuse);
    // The tiles this frame's resolve draws (CausticTiles.h), as quads in tileVertices_.
    int chooseTiles(const FrameContext& ctx, bool photons, bool history);

    gl::Program splat_, resolve_;
    gl::Texture accum_, rv_, r_;
    // The canvas tiles the photons reached this frame, and per history slot where it is not
    // 0 and the camera distance range of its resolved pixels (r32ui images, read back).
    gl::Texture photonTiles_, historyTiles_[2], historyNear_[2], historyFar_[2];
    gl::Buffer tileVertices_;  // vec2 NDC, six per run of tiles
    gl::VertexArray tileVao_;
    std::vector<std::uint8_t> tileMarks_;  // this frame's tiles, row-major
    // Last frame's history tiles, read back once per frame (by decide() or the resolve,
    // whichever asks first: the cache is mutable).
    mutable CausticHistoryTiles lastHistory_;
    mutable int historyReadFrame_ = -1;
    std::vector<std::uint32_t> photonTileFlags_;  // photonTiles_ read back
    // Smoothed irradiance for L_rv / L_r, a = camera distance (m); [history_.writeSlot()] is
    // written this frame and read as history by the next.
    gl::Texture historyRv_[2], historyR_[2];
    gl::Framebuffer fbo_[2];
    TemporalHistory history_;
    int framesSinceSplat_ = 0;  // frames since the photons were last splatted
    int width_ = 0, height_ = 0;
};

}  // namespace mirage::render
