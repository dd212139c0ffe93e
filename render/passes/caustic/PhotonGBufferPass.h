#pragma once
// Photon G-buffers (Knecht 2013 Sec. 5.2; docs/caustics.md): for every spot light whose cone
// holds a mirror or glass object, the specular objects rendered from the light (a frustum
// fitted to their bounding sphere, RendererOptions::caustic.mapSize^2 texels): per texel one
// reflected and one refracted photon (PGBuf_refl, PGBuf_refr) with its power by pixel counting
// and its receiver hit traced through the impostors. Camera-independent: reused while the scene,
// lights and plan stay.
#include "render/RenderPass.h"
#include "render/passes/impostor/ImpostorPass.h"

namespace mirage::render {

// Photon G-buffers, one layer per caustic spot light (causticMapSize^2): per texel of the
// specular objects seen from the light, the receiver hit of the reflected / refracted photon (xyz
// world; w = 4 x hit origin + the photon's real-path visibility, 0 = no photon) and its power
// (rgb W, a = visibility from the light through all occluders); and the receiver of each photon
// for reflected / refracted VPLs: packHalf2x16 of (normal.xy), (normal.z, diffuse albedo r),
// (albedo g, b), the normal facing the arriving photon.
inline constexpr Resource kPhotonHitRefl{"PhotonHitRefl"};
inline constexpr Resource kPhotonPowerRefl{"PhotonPowerRefl"};
inline constexpr Resource kPhotonHitRefr{"PhotonHitRefr"};
inline constexpr Resource kPhotonPowerRefr{"PhotonPowerRefr"};
inline constexpr Resource kPhotonSurfaceRefl{"PhotonSurfaceRefl"};
inline constexpr Resource kPhotonSurfaceRefr{"PhotonSurfaceRefr"};

class PhotonGBufferPass final : public RenderPass {
public:
    PhotonGBufferPass(const GpuScene& scene);
    const char* name() const override { return "photongbuf"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;
    bool cameraIndependent() const override { return true; }

private:
    ImpostorPass::TableViews impostorTables_;  // trace.glsl's tables, bound every frame
    SceneTableViews sceneTables_;              // materials and specular draws, likewise
    gl::Program backProgram_, photonProgram_;
    gl::Texture backPosition_, backNormal_, depth_;
    gl::Texture reflHit_, reflPower_, refrHit_, refrPower_, reflSurface_, refrSurface_;
    gl::Framebuffer backFbo_, photonFbo_;
    int allocatedSize_ = 0, allocatedLayers_ = 0;
    MaterialDraw photonDraw_{photonProgram_};  // after photonProgram_
};

}  // namespace mirage::render
