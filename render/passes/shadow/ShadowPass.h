#pragma once
// Shadow maps for every light with a caster in its cone (spot: 1 layer, point: 6 cube-face
// layers, directional: 1 ortho layer), stored as occluder distance in an R32F array texture.
// Visibility is tested twice (docs/realtime-renderer.md "Real and virtual: routing"): against all
// occluders (for L_rv) and against real occluders only (for L_r). The second map is rendered only
// for real lights with a virtual caster in the cone; elsewhere it is the same as the first and
// aliases it. When VPLs are needed the all-occluder pass also writes the reflective shadow maps; at
// their own size (ShadowOptions::rsmSize) when it differs from the shadow map's, in a second
// raster. Glass (DrawItem::transmissive) in a light's cone is left out of the occluder maps and
// drawn into the glass atlases instead (shadow_glass.frag): the lookups colour the light behind it
// by its Fresnel-, colour- and Beer-Lambert-weighted transmittance; mirrors stay opaque. A
// translucent object (DrawItem::translucent) goes into the same atlases for every light (caustic
// lights too): its boundary's Fresnel and its medium's optical thickness along the light's ray.
// Focused virtual occluders (LightPlan::focusDraws): ShadowMaps' layers after the lights' hold
// the virtual occluders in groups, each rendered through the frustum fitted to its group
// (GpuLight::focusViewProj), ShadowMapsReal the real ones over the light's frustum, and the RSM
// (every surface) its own raster.
#include "render/RenderPass.h"

namespace mirage::render {

// Per light layer (shadow atlas: shadowMapSize^2 x layers).
inline constexpr Resource kShadowMaps{"ShadowMaps"};  // distance to the nearest occluder (m)
// The same with real occluders only (aliases ShadowMaps where equal).
inline constexpr Resource kShadowMapsReal{"ShadowMapsReal"};
// Glass between light and texel: rgb = sum of ln(transmittance) terms (Fresnel, colour,
// Beer-Lambert), a = nearest glass (m); and the same with real glass only.
inline constexpr Resource kShadowGlass{"ShadowGlass"};
inline constexpr Resource kShadowGlassReal{"ShadowGlassReal"};
// Reflective shadow map (rsmSize^2 x layers): rgb reflected intensity, a = real; normal facing the
// light; xyz world (m), w = 1 where covered.
inline constexpr Resource kRsmFlux{"RsmFlux"};
inline constexpr Resource kRsmNormal{"RsmNormal"};
inline constexpr Resource kRsmPosition{"RsmPosition"};

class ShadowPass final : public RenderPass {
public:
    ShadowPass();
    const char* name() const override { return "shadow"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;
    bool cameraIndependent() const override { return true; }

private:
    enum class Occluders { All, Real, Unfocused };  // Unfocused: LightPlan::unfocusedDraws
    void beginLayer(const gl::Texture& distance, int atlasLayer, bool rsm);
    void renderLayer(FrameContext& ctx, int light, int layer, Occluders which, bool rsm);
    void renderRsmLayer(FrameContext& ctx, int light, int layer);
    void renderFocusLayer(FrameContext& ctx, int light, int focusMap);
    void drawOccluders(FrameContext& ctx, int light, int layer, Occluders which, bool rsm);
    bool separateRsm() const { return rsmSize_ != allocatedSize_; }
    void renderGlassLayer(FrameContext& ctx, int light, int layer, bool realOnly);
    void setMediumUniforms(const DrawItem& d, const GpuMedium* medium);
    gl::Program program_, glassProgram_;
    gl::Texture distance_, distanceReal_, rsmFlux_, rsmNormal_, rsmPosition_, depth_, rsmDepth_;
    gl::Texture glass_, glassReal_;
    gl::Framebuffer fbo_, glassFbo_, rsmFbo_;
    int allocatedLayers_ = 0, allocatedFocusLayers_ = 0, allocatedSize_ = 0, rsmSize_ = 0;
    MaterialDraw draw_{program_};  // after program_
    MaterialDraw glassDraw_{glassProgram_};
    GLint locViewProj_ = -1, locLight_ = -1, locGlassLayer_ = -1, locGlassScale_ = -1;
    GLint locGlassViewProj_ = -1, locGlassLight_ = -1;
    GLint locTranslucent_ = -1, locExtinction_ = -1, locShadowScale_ = -1, locIor_ = -1,
          locHasDensity_ = -1, locLocalFromWorld_ = -1, locDensityMin_ = -1, locDensityMax_ = -1,
          locDensityCells_ = -1;
};

}  // namespace mirage::render
