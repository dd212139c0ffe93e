#include "render/passes/composite/CompositeVersion.h"

#include "render/FrameGraph.h"
#include "render/passes/composite/CompositePass.h"

namespace mirage::render {

void CompositeVersion::declare(PassBuilder& b) {
    b.modify(kComposite, {GL_RGBA32F, SizeRule::Camera, Storage::PassOwned});
    b.modify(kCompositeSrgb, {GL_SRGB8_ALPHA8, SizeRule::Camera, Storage::PassOwned});
}

void CompositeVersion::resize(int width, int height) {
    if (linear_.width() == width && linear_.height() == height) return;
    linear_ = gl::Texture::create2D(label_ + " linear", width, height, GL_RGBA32F);
    srgb_ = gl::Texture::create2D(label_ + " srgb", width, height, GL_SRGB8_ALPHA8);
    fbo_ = gl::Framebuffer(label_ + " fbo");
    fbo_.attachColor(0, linear_);
    fbo_.attachColor(1, srgb_);
    fbo_.finalize(2);
}

void CompositeVersion::publish(PassResources& res) const {
    res.publish(kComposite, linear_);
    res.publish(kCompositeSrgb, srgb_);
}

}  // namespace mirage::render
