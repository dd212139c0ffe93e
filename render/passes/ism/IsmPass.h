#pragma once
// Imperfect shadow maps for VPL visibility: one paraboloid tile per VPL in an r32ui atlas,
// filled by point splatting in compute. A second atlas with real points only gives L_r's
// visibility; it is skipped (aliased to the first) when the pool has no virtual points.
#include "render/RenderPass.h"

namespace mirage::render {

class VplPass;

class IsmPass final : public RenderPass {
public:
    explicit IsmPass(const VplPass& vpls);
    const char* name() const override { return "ism"; }
    std::vector<Resource> reads() const override { return {Resource::Vpls}; }
    std::vector<Resource> writes() const override {
        return {Resource::ImperfectShadowMaps, Resource::ImperfectShadowMapsReal};
    }
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx) override;
    bool cameraIndependent() const override { return true; }
    void publishCached(FrameContext& ctx) override;
    static int tilesPerRow(int vplCount);

private:
    const VplPass& vpls_;
    gl::Program program_;
    gl::Texture all_, real_;
    int allocatedSize_ = 0;
};

}  // namespace mirage::render
