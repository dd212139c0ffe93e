#pragma once
// Imperfect shadow maps for VPL visibility: one paraboloid tile per VPL in an r32ui atlas,
// filled by point splatting in compute. A second atlas with real points only gives L_r's
// visibility; it is skipped (aliased to the first) when the pool has no virtual points.
#include "render/RenderPass.h"

namespace mirage::render {

// r32ui atlas, one paraboloid tile per VPL (all occluders), and the same with real points only
// (aliases the first without them).
inline constexpr Resource kImperfectShadowMaps{"ImperfectShadowMaps"};
inline constexpr Resource kImperfectShadowMapsReal{"ImperfectShadowMapsReal"};

class IsmPass final : public RenderPass {
public:
    IsmPass();
    const char* name() const override { return "ism"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;
    bool cameraIndependent() const override { return true; }

    // Levels of the pull-push pyramid above the atlas for tiles of `tileSize` texels: halvings
    // while the level's tiles stay even and at least 4 texels wide (64: 4 levels, to 4x4).
    static int pullPushLevels(int tileSize);

private:
    // Fills the gaps of one atlas (ism_pullpush.comp): pull into pyramid_, push back.
    void pullPush(const FrameContext& ctx, const gl::Texture& atlas);

    gl::Program program_, pullPush_;
    gl::Texture all_, real_;
    // Depth and coverage (RG32F) of the pull-push pyramid: mip level L - 1 holds level L
    // (half the atlas's size at mip 0).
    gl::Texture pyramid_;
    int allocatedSize_ = 0, allocatedLevels_ = 0;
};

}  // namespace mirage::render
