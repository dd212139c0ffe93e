#pragma once
// Geometry the specular passes need besides the primary G-buffer (canvas size, camera view):
// BackFacePosition / BackFaceNormal, the back faces of the specular (glass) objects, nearest
// first (world position, specular slot and outward normal): Wyman 2005's first pass, from which
// the refraction pass finds where a refracted ray leaves the object. (The nearest real surface
// per pixel, RealSurfaces, comes from the G-buffer pass.)
#include "render/RenderPass.h"

namespace mirage::render {

// Specular objects' back faces (canvas size): xyz world, w = slot + 1; xyz outward unit normal.
inline constexpr Resource kBackFacePosition{"BackFacePosition"};
inline constexpr Resource kBackFaceNormal{"BackFaceNormal"};

class BackFacePass final : public RenderPass {
public:
    BackFacePass();
    const char* name() const override { return "backface"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    gl::Program program_;
    gl::Texture position_, normal_, depth_;
    gl::Framebuffer fbo_;
    DrawnRects drawn_;
    GLint locModel_ = -1, locNormal_ = -1, locSlot_ = -1;
    int width_ = 0, height_ = 0;
};

}  // namespace mirage::render
