#pragma once
// Shadow maps for every light with a caster in its cone (spot: 1 layer, point: 6 cube-face
// layers, directional: 1 ortho layer), stored as occluder distance in an R32F array texture.
// Visibility is tested twice (DESIGN.md "Real and virtual"): against all occluders (for L_rv)
// and against real occluders only (for L_r). The second map is rendered only for real lights
// with a virtual caster in the cone; elsewhere it is the same as the first and aliases it.
// When VPLs are needed the all-occluder pass also writes the reflective shadow maps.
#include "render/RenderPass.h"

namespace mirage::render {

class ShadowPass final : public RenderPass {
public:
    ShadowPass();
    const char* name() const override { return "shadow"; }
    std::vector<Resource> reads() const override { return {}; }
    std::vector<Resource> writes() const override {
        return {Resource::ShadowMaps, Resource::ShadowMapsReal, Resource::ReflectiveShadowMaps};
    }
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx) override;
    bool cameraIndependent() const override { return true; }
    void publishCached(FrameContext& ctx) override;

    const gl::Texture& rsmFlux() const { return rsmFlux_; }
    const gl::Texture& rsmNormal() const { return rsmNormal_; }
    const gl::Texture& rsmPosition() const { return rsmPosition_; }

private:
    void renderLayer(FrameContext& ctx, int light, int layer, bool realOnly, bool rsm);
    gl::Program program_;
    gl::Texture distance_, distanceReal_, rsmFlux_, rsmNormal_, rsmPosition_, depth_;
    gl::Framebuffer fbo_;
    int allocatedLayers_ = 0, allocatedSize_ = 0;
    GLint locModel_ = -1, locNormal_ = -1, locViewProj_ = -1, locLight_ = -1, locMaterial_ = -1,
          locOrigin_ = -1;
};

}  // namespace mirage::render
