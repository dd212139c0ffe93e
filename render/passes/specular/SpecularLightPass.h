#pragma once
// L'_rv, L'_r and L_env (Knecht 2013 Eqs. 3-5, Sec. 4.1.3): the reflected and refracted hits of
// GBuf_refl / GBuf_refr lit by every light (shadow maps), the environment (SH) and the VPLs
// (imperfect shadow maps), Fresnel-weighted and routed real / virtual; rays that hit nothing
// modelled look up the environment map into L_env (specular_light.frag). In frames with a
// world-space photon grid (PhotonGridPass) the hits also gather the caustic photons around them
// (a shader variant: without a grid the frame pays nothing for it). L'_rv, L'_r and the
// reflection's share are smoothed over time (RendererOptions::specular.temporal): they and the
// hits they were lit at ping-pong, this frame's result being the next frame's history (not in the
// half-resolution variant, RendererOptions::specular.halfResolution: its hits are shaded per 2x2
// block, and the history test needs each pixel's own hits). With specular.refreshInterval N > 1
// only one phase of N of the 8x8-pixel tiles is shaded per frame; the other tiles' pixels take
// their history as it is where it was lit at this frame's hits (specular_light.frag).
#include "render/RenderPass.h"
#include "render/TemporalHistory.h"

namespace mirage::render {

// L'_rv (Eq. 3, Fresnel-weighted), L'_r (Eq. 4) and the reflection's share of L'_r, after
// temporal smoothing (RGBA32F; version 0 is this pass's history, persistent); L_env, the
// environment seen where a ray leaves the modelled scene. SpecularRv.a = the specular surface's
// camera distance (m, 0: none); SpecularR.a and SpecularRReflection.a = y and z of the refracted
// ray's hit (world, m). The fuzzy and rough passes write later versions of all four (filtered on
// their pixels, the version before elsewhere).
inline constexpr Resource kSpecularRv{"SpecularRv"};
inline constexpr Resource kSpecularR{"SpecularR"};
inline constexpr Resource kSpecularRReflection{"SpecularRReflection"};
inline constexpr Resource kLenv{"Lenv"};

class SpecularLightPass final : public RenderPass {
public:
    SpecularLightPass(const GpuScene& scene, const RendererOptions& options);
    const char* name() const override { return "speclight"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    struct Variant {
        gl::Program program;
        GLint useVpls = -1, vplStride = -1, cellSize = -1, gatherCap = -1, historyWeight = -1;
        GLint refreshInterval = -1, refreshPhase = -1;
    };
    // Per kind of rectangle: [0] with glass (both rays), [1] mirrors and metals alone
    // (MIRAGE_REFLECTION_ONLY; FrameContext::mirrorRects).
    static constexpr int kKinds = 2;
    static Variant makeVariant(const std::string& label, const std::string& defines, int kind);
    // The variants of `kind` (full resolution), built on first use if the scene did not need them.
    void buildFull(const GpuScene& scene, int kind);
    void buildHalfResolution(const GpuScene& scene, int kind);
    void allocateHalfResolution(int w, int h);
    std::string refreshNote(const FrameContext& ctx) const;
    void setUniforms(const FrameContext& ctx, const PassResources& res, const Variant& v) const;
    void shadeHalfResolution(FrameContext& ctx, PassResources& res, bool gather, int write);
    // Clears fbo_[write] (bound) where the last draws into its textures and this frame's cover,
    // then draws each kind's rectangles with its variant (plain or gather), `program` of which is
    // put in use with its uniforms and the frame's blocks.
    void clearAndDraw(FrameContext& ctx, const PassResources& res, int write,
                      const Variant (&variants)[kKinds]);
    void drawKinds(FrameContext& ctx, const PassResources& res, const Variant (&variants)[kKinds],
                   const std::vector<glm::ivec4> (&rects)[kKinds], int width, int height);
    Variant plain_[kKinds], gather_[kKinds];  // gather_: only for scenes that can have caustics
    // Smoothed L'_rv, L'_r, reflection share (Resource.h), L_env and the hits they were lit at
    // (read by this pass alone, so not a frame-graph resource), fbo_[i]'s attachments 0-4:
    // [history_.writeSlot()] is written and published this frame and read as history by the next.
    gl::Texture rv_[2], r_[2], rRefl_[2], env_[2], hits_[2];
    gl::Framebuffer fbo_[2];
    DrawnRects drawn_[2];              // what draws covered in each fbo_'s attachments
    GLuint attachedMask_[2] = {0, 0};  // the SpecularMask texture attached as fbo_[i]'s depth
    gl::Texture vplTexels_ = gl::Texture::createBufferView("VPL texels (specular light)");
    TemporalHistory history_;
    int width_ = 0, height_ = 0;
    // RendererOptions::specular.halfResolution: the half-resolution variants (built on first use),
    // the upsample, the half-size specular-pixel mask and hit radiance.
    bool sceneCanGather_ = false;
    Variant halfPlain_[kKinds], halfGather_[kKinds];
    gl::Program resolve_[kKinds], halfMaskProgram_;
    gl::Texture halfReflRv_, halfReflR_, halfRefrRv_, halfRefrR_, halfMask_;
    gl::Framebuffer halfFbo_, halfMaskFbo_;
    DrawnRects halfDrawn_, halfMaskDrawn_;
    int halfWidth_ = 0, halfHeight_ = 0;
};

}  // namespace mirage::render
