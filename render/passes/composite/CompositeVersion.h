#pragma once
// A new version of the composite, as the passes after the composite write it (anti-aliasing,
// motion blur, grain, the resource view): camera-size targets, linear RGBA32F (colour 0) and
// sRGB8 (colour 1, encoded by GL_FRAMEBUFFER_SRGB) written by one draw, and published as
// Composite and CompositeSrgb.
#include <string>

#include "core/gl/Objects.h"

namespace mirage::render {

class PassBuilder;
class PassResources;

class CompositeVersion {
public:
    explicit CompositeVersion(std::string label) : label_(std::move(label)) {}
    // The pass's declarations: it modifies Composite and CompositeSrgb (PassBuilder::modify).
    static void declare(PassBuilder& b);
    // (Re)allocates the targets for a camera of width x height; returns at once when unchanged.
    void resize(int width, int height);
    // Binds the framebuffer over both targets.
    void bind() { fbo_.bind(); }
    void publish(PassResources& res) const;

private:
    std::string label_;
    gl::Texture linear_, srgb_;
    gl::Framebuffer fbo_;
};

}  // namespace mirage::render
