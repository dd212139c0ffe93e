#pragma once
// Options of rough glass (render/passes/rough, docs/specular.md "Rough refraction").
#include "render/PassOptions.h"

namespace mirage::render {

// How rough glass blurs what is seen through it.
enum class RoughRefractionMethod {
    Filter,  // the fuzzy pass's image-space filter with the transmitted lobe (render/passes/fuzzy)
    Lean,    // LEAN-mapped back-face normals, one Gaussian lobe per pixel (render/passes/rough)
    Gsr,     // the same with the back NDF reduced to one Gaussian per hemisphere subdivision
};
const char* roughRefractionMethodName(RoughRefractionMethod m);  // "filter", "lean", "gsr"

struct RoughOptions {
    RoughRefractionMethod method = RoughRefractionMethod::Lean;
    int gsrSubdivisions = 4;  // the hemisphere sectors of the Gaussian sum reduction (1..8)
    // Levels of the LEAN moment chains and of the prefiltered lookups (camera image, rough-glass
    // radiance; 1..12): a lobe wider than the last level is cut there.
    int mipLevels = 8;
    // How far a turn of the exit ray moves what the lobe sees in the glass's image: by ray
    // differentials (the sharp path's exit point and direction at the neighbouring pixels: true)
    // or by a flat slab's magnification (false). A sphere's rim, where the exit direction sweeps
    // the surroundings within a few pixels, needs the first: the slab model spreads its lobe over
    // the interior's image.
    bool rayDifferentials = true;

    void validate() const {
        checkOption(gsrSubdivisions >= 1 && gsrSubdivisions <= 8, "rough.gsrSubdivisions",
                    "1..8 hemisphere sectors", gsrSubdivisions);
        checkOption(mipLevels >= 1 && mipLevels <= 12, "rough.mipLevels", "1..12 mip levels",
                    mipLevels);
    }
};

}  // namespace mirage::render
