#pragma once
// Primary G-buffer (GBuf_p of Knecht 2013 Sec. 5.1) from the tracked camera, rendered
// undistorted onto the canvas of CameraProjection with the calibrated fx, fy.
//
// It also gives RealSurfaces: the nearest REAL surface per pixel (world position + origin), which
// the back-projection of the video into reflections and refractions validates against (Knecht
// 2013 Sec. 4.1.3; the video shows real surfaces only, virtual objects in front do not hide them).
// When virtual draws are present and a mirror or glass object is in view (the only frames whose
// passes read it), the real draws are rasterised first, writing their position into RealSurfaces
// too (a fifth target), and the virtual draws follow with that target masked off: one raster of
// the scene instead of a second raster of every real draw, and no copy of the position target
// between the two halves (on llvmpipe a copy waits for the rasteriser). Otherwise the position
// target itself is published as RealSurfaces.
//
// With a mirror or glass object in view it also gives SpecularMask, a canvas depth buffer: 0 on
// the pixels that show one, 1 elsewhere (specular_mask.frag), drawn over the specular objects'
// rectangles only. The specular passes shade only those pixels, the diffuse lighting passes all
// the others (FrameContext::drawFullscreenTriangleOutsideSpecular).
#include <vector>

#include "render/RenderPass.h"

namespace mirage::render {

// The primary G-buffer (canvas size).
inline constexpr Resource kGBufferPosition{"GBufferPosition"};  // xyz world (m), w = origin
                                                                // (ORIGIN_*, 0 = empty)
inline constexpr Resource kGBufferNormal{"GBufferNormal"};  // xyz unit world normal, w = roughness
inline constexpr Resource kGBufferAlbedo{"GBufferAlbedo"};  // rgb linear base colour, a = metallic
// rgb linear emitted radiance, a = specular slot + 1 (0 = not specular, -1 = translucent)
inline constexpr Resource kGBufferEmissive{"GBufferEmissive"};
// The nearest REAL surface per pixel: xyz world, w = origin.
inline constexpr Resource kRealSurfaces{"RealSurfaces"};
// Depth 0 on specular pixels, 1 elsewhere: the passes that shade only those test against it
// (early depth test skips the rest).
inline constexpr Resource kSpecularMask{"SpecularMask"};

class GBufferPass final : public RenderPass {
public:
    // Which material textures the scene's draws have: the shader reads only those (llvmpipe pays
    // for every texture read, of a white stand-in as much as of a real texture).
    struct MaterialMaps {
        bool baseColor = true;
        bool metallicRoughness = true;
    };
    GBufferPass() : GBufferPass(MaterialMaps{}) {}
    explicit GBufferPass(MaterialMaps maps);
    const char* name() const override { return "gbuffer"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    // A mirror or glass object is in view: the frame's specular passes run.
    static bool specularInView(const FrameContext& ctx);
    // True when this frame needs RealSurfaces apart from the G-buffer position (see above).
    static bool separateRealSurfaces(const FrameContext& ctx);

    gl::Program program_;
    gl::Program maskProgram_;  // specular_mask.frag
    gl::Texture position_, normal_, albedo_, emissive_, depth_, realSurfaces_, mask_;
    gl::Framebuffer fbo_, maskFbo_;
    DrawnRects maskDrawn_;         // what the last mask draw covered (cleared to 1 before the next)
    MaterialDraw draw_{program_};  // after program_
    GLint locSpecularSlot_ = -1;
    std::vector<int> specularSlot_;  // per draw: its index in specularDraws(), -1 = not specular
};

}  // namespace mirage::render
