// The rough-refraction pass's knobs (render/PassKnob.h).
#include <array>

#include "render/PassKnob.h"

namespace mirage::render {

std::vector<PassKnob> roughKnobs() {
    std::vector<PassKnob> k{
        PassKnob{
            "rough_method",
            "how rough glass blurs what is seen through it: lean (LEAN-mapped back faces, one "
            "lobe), gsr (Gaussian sum reduction, one lobe per hemisphere subdivision) or filter "
            "(the fuzzy pass's image-space filter)",
            {"lean"},
            {},
            [](RendererOptions& o, const std::string& v) {
                o.rough.method = std::array{RoughRefractionMethod::Lean, RoughRefractionMethod::Gsr,
                                            RoughRefractionMethod::Filter}[parseKnobChoice(
                    "rough_method", v, {"lean", "gsr", "filter"})];
            },
            [](const RendererOptions& o) {
                return std::string(roughRefractionMethodName(o.rough.method));
            }},
        intKnob("gsr_subdivisions", "hemisphere sectors of the Gaussian sum reduction (1..8)",
                [](RendererOptions& o) -> int& { return o.rough.gsrSubdivisions; }, 1, 8, {"4"}),
        intKnob(
            "lean_mip_levels",
            "mip levels of the rough-refraction chains (LEAN moments, camera image, rough-glass "
            "radiance; 1..12): a wider lobe is cut at the last",
            [](RendererOptions& o) -> int& { return o.rough.mipLevels; }, 1, 12, {"8"}),
        choiceKnob("rough_footprint",
                   "how far a turn of the rough glass's exit ray moves what it sees: "
                   "differentials (the sharp path's neighbouring pixels) or slab (a flat slab's "
                   "magnification)",
                   [](RendererOptions& o) -> bool& { return o.rough.rayDifferentials; },
                   "differentials", "slab", {"differentials"}),
    };
    return k;
}

}  // namespace mirage::render
