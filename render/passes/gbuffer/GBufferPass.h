#pragma once
// Primary G-buffer (GBuf_p of Knecht 2013 Sec. 5.1) from the tracked camera, rendered
// undistorted onto the canvas of CameraProjection with the calibrated fx, fy.
#include "render/RenderPass.h"

namespace mirage::render {

class GBufferPass final : public RenderPass {
public:
    // metallicRoughnessMaps false: the shader skips the metallic-roughness texture read (a scene
    // without such textures; llvmpipe pays for every texture read).
    explicit GBufferPass(bool metallicRoughnessMaps = true);
    const char* name() const override { return "gbuffer"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    gl::Program program_;
    gl::Texture position_, normal_, albedo_, emissive_, depth_;
    gl::Framebuffer fbo_;
    MaterialDraw draw_{program_};  // after program_
    GLint locSpecularSlot_ = -1;
};

}  // namespace mirage::render
