#pragma once
// GBuf_refl and GBuf_refr (Knecht 2013 Sec. 5.1): per camera pixel showing a mirror or glass
// object, the surface hit by the reflected ray and by the two-interface refracted ray (Wyman
// 2005, using the back-face pass), with the Fresnel / transmittance weight of each
// (specular_gbuffer.frag says how; docs/specular.md). Hits come from traceSurroundings (the
// impostor helper's reflected-scene impostors, render/passes/impostor/trace.glsl).
#include "render/RenderPass.h"
#include "render/passes/impostor/ImpostorPass.h"

namespace mirage::render {

// GBuf_refl: the reflected-ray hit position + origin (or the ray on a miss), normal (w =
// roughness), base colour (a = metallic), emission (a = specular-pixel flag), Fresnel weight (a =
// distance inside); GBuf_refr: the same for the two-interface refracted ray (Wyman 2005).
inline constexpr Resource kReflectionGBuffer{"ReflectionGBuffer"};
inline constexpr Resource kReflectionNormal{"ReflectionNormal"};
inline constexpr Resource kReflectionAlbedo{"ReflectionAlbedo"};
inline constexpr Resource kReflectionEmissive{"ReflectionEmissive"};
inline constexpr Resource kReflectionWeight{"ReflectionWeight"};
inline constexpr Resource kRefractionGBuffer{"RefractionGBuffer"};
inline constexpr Resource kRefractionNormal{"RefractionNormal"};
inline constexpr Resource kRefractionAlbedo{"RefractionAlbedo"};
inline constexpr Resource kRefractionEmissive{"RefractionEmissive"};
inline constexpr Resource kRefractionWeight{"RefractionWeight"};

// One specular G-buffer: hit position + origin (or the ray direction on a miss), normal +
// roughness, albedo + metallic, emission + specular-pixel flag, weight + distance inside.
struct SpecularHitBuffer {
    gl::Texture position, normal, albedo, emissive, weight;
    gl::Framebuffer fbo;
    DrawnRects drawn;  // of all five
};

class SpecularGBufferPass final : public RenderPass {
public:
    // `prepareHalfPrograms`: the half-resolution trace's programs are built now, not on first use.
    explicit SpecularGBufferPass(bool prepareHalfPrograms = false);
    const char* name() const override { return "specgbuf"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    // One ray pair per pixel into refl_ / refr_, or (halfResolutionTrace) per 2x2 block into the
    // half-size buffers, then filled into refl_ / refr_.
    void traceFullResolution(FrameContext& ctx);
    void traceHalfResolution(FrameContext& ctx, PassResources& res);
    void allocateHalfResolution();
    void buildHalfPrograms();

    ImpostorPass::TableViews impostorTables_;  // trace.glsl's tables, bound every frame
    SceneTableViews sceneTables_;              // materials and specular draws, likewise
    gl::Program programs_[2];  // [0] reflection, [1] refraction (MIRAGE_SPECULAR_MODE)
    GLuint attachedMask_ = 0;  // the SpecularMask texture attached as both hit buffers' depth
    SpecularHitBuffer refl_, refr_;
    int width_ = 0, height_ = 0;
    // RendererOptions::specular.halfResolutionTrace (allocated on first use; the programs then
    // too, or when the pass is made with prepareHalfPrograms): the
    // half-resolution trace's programs, its fill's, the half-size hits and specular-block mask.
    gl::Program halfPrograms_[2], fillPrograms_[2], halfMaskProgram_;
    SpecularHitBuffer halfRefl_, halfRefr_;
    gl::Texture halfMask_;
    gl::Framebuffer halfMaskFbo_;
    DrawnRects halfMaskDrawn_;
    int halfWidth_ = 0, halfHeight_ = 0;
};

}  // namespace mirage::render
