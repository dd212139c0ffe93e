#pragma once
// Geometry the specular passes need besides the primary G-buffer (canvas size, camera view):
//  - BackFacePosition / BackFaceNormal: the back faces of the specular (glass) objects, nearest
//    first (world position, specular slot and outward normal): Wyman 2005's first pass, from
//    which the refraction pass finds where a refracted ray leaves the object;
//  - RealSurfaces: the nearest REAL surface per pixel (world position). The camera image shows
//    real surfaces only, so a point back-projected into it is valid only if it is that surface
//    (Knecht 2013 Sec. 4.1.3); virtual objects in front do not hide it in the video. When the
//    scene has no virtual geometry the primary G-buffer is that buffer and is published instead.
#include "render/RenderPass.h"

namespace mirage::render {

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
    gl::Texture position_, normal_, depth_, realPosition_, realDepth_;
    gl::Framebuffer fbo_, realFbo_;
    GLint locModel_ = -1, locNormal_ = -1, locMode_ = -1, locSlot_ = -1;
    int width_ = 0, height_ = 0;
};

}  // namespace mirage::render
