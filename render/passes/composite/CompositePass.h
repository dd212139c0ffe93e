#pragma once
// The compositor: differential rendering of L_rv / L_r into the camera image, with the lens
// distortion applied through the remap table (docs/realtime-renderer.md).
#include "render/RenderPass.h"

namespace mirage::render {

class GBufferPass;
class BackFacePass;
class SpecularGBufferPass;
class SpecularLightPass;

class CompositePass final : public RenderPass {
public:
    explicit CompositePass(const GBufferPass& gbuffer);
    const char* name() const override { return "composite"; }
    std::vector<Resource> reads() const override { return {Resource::CameraImage}; }
    std::vector<Resource> writes() const override { return {Resource::Composite}; }
    PassDecision decide(const FrameContext& ctx) const override;
    // The specular passes whose outputs Eqs. 6-11 composite (pixels showing mirror / glass).
    void setSpecular(const SpecularGBufferPass* hits, const SpecularLightPass* light,
                     const BackFacePass* backFaces) {
        specHits_ = hits;
        specLight_ = light;
        backFaces_ = backFaces;
    }
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx) override;

    // Output (camera image size, top row first): linear RGBA32F (a = coverage) and sRGB8.
    const gl::Texture& linear() const { return linear_; }
    const gl::Texture& srgb() const { return srgb_; }

private:
    const GBufferPass& gbuffer_;
    // Two variants: llvmpipe runs both sides of every branch (SIMD masks), so the specular
    // compositing code would cost every frame even behind a uniform that turns it off.
    gl::Program program_;         // with Eqs. 6-11 for mirror / glass pixels
    gl::Program programDiffuse_;  // MIRAGE_DIFFUSE_ONLY: frames without specular objects
    const SpecularGBufferPass* specHits_ = nullptr;
    const SpecularLightPass* specLight_ = nullptr;
    const BackFacePass* backFaces_ = nullptr;
    gl::Texture linear_, srgb_, remap_;
    // Canvas size, RG32F: the camera-image pixel (OpenCV convention) that sees each canvas
    // pixel's ray (CameraIntrinsics::project), -1e4 where none does: CI(x) of Eq. 8-10.
    gl::Texture canvasToCamera_;
    GLint locEpsilon_ = -1;
    gl::Framebuffer fbo_;
};

}  // namespace mirage::render
