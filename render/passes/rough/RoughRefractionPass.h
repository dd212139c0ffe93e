#pragma once
// Rough refraction (Zeng and Wyman, "Real-time rough refraction via LEAN mapping and Gaussian sum
// reduction"; docs/specular.md, "Rough refraction"): after the specular passes traced and lit
// each rough-glass pixel's sharp two-interface path, a Gaussian lobe is carried through the
// glass (the front BTDF from the roughness, the back faces' normal distribution LEAN-mapped into
// mip chains, or reduced to one Gaussian per hemisphere sector by GSR) and what it sees is looked
// up blurred: the glass's resolved buffers (rendered radiance of the hits, environment,
// back-projected camera image) from coverage-weighted mip chains at the lobe's footprint. Writes
// the five buffers the composite reads for filtered pixels (the fuzzy pass's, or the sharp ones,
// pass through elsewhere). Runs only when the scene has rough glass (transmission, roughness above
// Material::kMirrorMaxRoughness) and the method is LEAN or GSR, over the specular scissor
// rectangle.
#include <glm/glm.hpp>

#include "render/RenderPass.h"

namespace mirage::render {

class RoughRefractionPass final : public RenderPass {
public:
    RoughRefractionPass();
    const char* name() const override { return "roughrefr"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    static constexpr int kChains = 8;
    gl::Program prefilter_, refraction_;
    // chains_: LEAN moments (mean, squares, products), then the coverage-weighted L'_rv, L'_r,
    // reflection share, L_env and video term (mip-mapped); out_: the published buffers.
    gl::Texture chains_[kChains], out_[5];
    gl::Texture canvasToCamera_;  // CameraProjection::canvasToCameraTable, RG32F
    gl::Framebuffer chainsFbo_, outFbo_;
    DrawnRects chainsDrawn_, outDrawn_;  // what the draws into each last covered (level 0)
    GLint locPrefilterEpsilon_ = -1, locMethod_ = -1, locSubdivisions_ = -1, locFocal_ = -1,
          locMaxLevel_ = -1, locFootprint_ = -1;
    int width_ = 0, height_ = 0, levels_ = 0;
};

}  // namespace mirage::render
