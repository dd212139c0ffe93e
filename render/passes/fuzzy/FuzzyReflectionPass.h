#pragma once
// Fuzzy reflections of rough metals (Kulikova and Dmitriev, "Fuzzy reflections", an image-space
// filter; docs/specular.md): after the specular passes traced and lit each rough-metal pixel's
// MIRROR ray, the reflection is blurred over the pixel's reflection cone. Filtered: L'_rv, L'_r,
// the reflection's share of L'_r, L_env and the reflection's video term (resolved per pixel with
// the composite's depth-validated back-projection), so the composite applies Eqs. 6-11 unchanged
// to blurred lookups. Runs only when the scene has a rough reflector (metal with roughness in
// (Material::kMirrorMaxRoughness, kRoughReflectorMaxRoughness]) and only over its pixels.
#include <vector>

#include <glm/glm.hpp>

#include "render/RenderPass.h"

namespace mirage::render {

// The filtered video term of a rough reflection or refraction (rgb camera units: eta1
// CI_r(p_refl) or the rendered real share; a = 1 on a filtered pixel): created by this pass,
// a new version written by the rough pass.
inline constexpr Resource kFilteredVideo{"FilteredVideo"};

class FuzzyReflectionPass final : public RenderPass {
public:
    FuzzyReflectionPass();
    const char* name() const override { return "fuzzy"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    gl::Program resolve_, filter_;
    // video_: the resolved video term (the fifth filter input); rows_: the row pass's five
    // outputs; out_: the column pass's (published).
    gl::Texture video_, rows_[5], out_[5];
    gl::Texture canvasToCamera_;  // CameraProjection::canvasToCameraTable, RG32F
    gl::Framebuffer videoFbo_, rowsFbo_, outFbo_;
    DrawnRects videoDrawn_, rowsDrawn_, outDrawn_;  // what the draws into each last covered
    GLint locGlassResolve_ = -1, locGlassFilter_ = -1;
    GLint locEpsilon_ = -1, locStep_ = -1, locCone_ = -1, locFocal_ = -1, locTaps_ = -1;
    int width_ = 0, height_ = 0;
};

}  // namespace mirage::render
