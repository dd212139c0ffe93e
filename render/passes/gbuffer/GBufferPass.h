#pragma once
// Primary G-buffer (GBuf_p of Knecht 2013 Sec. 5.1) from the tracked camera, rendered
// undistorted onto the canvas of CameraProjection with the calibrated fx, fy.
#include "render/RenderPass.h"

namespace mirage::render {

class GBufferPass final : public RenderPass {
public:
    GBufferPass();
    const char* name() const override { return "gbuffer"; }
    std::vector<Resource> reads() const override { return {}; }
    std::vector<Resource> writes() const override { return {Resource::GBuffer}; }
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx) override;

    // G-buffer attachments (canvas size), valid after resize().
    const gl::Texture& position() const { return position_; }
    const gl::Texture& normal() const { return normal_; }
    const gl::Texture& albedo() const { return albedo_; }
    const gl::Texture& emissive() const { return emissive_; }  // a = specular slot + 1
    const gl::Texture& depth() const { return depth_; }

private:
    gl::Program program_;
    gl::Texture position_, normal_, albedo_, emissive_, depth_;
    gl::Framebuffer fbo_;
    GLint locModel_ = -1, locNormal_ = -1, locMaterial_ = -1, locOrigin_ = -1,
          locSpecularSlot_ = -1;
};

}  // namespace mirage::render
