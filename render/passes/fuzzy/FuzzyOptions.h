#pragma once
// Options of the fuzzy reflections of rough metals (render/passes/fuzzy, docs/specular.md).
#include "render/PassOptions.h"

namespace mirage::render {

// The image-space filter (Kulikova and Dmitriev, Eqs. 1-5) over the mirror-ray buffers.
struct FuzzyOptions {
    // false: the rough metal's reflection stays sharp (its roughness ignored; for comparison).
    bool enabled = true;
    float coneDeg =
        20.0f;      // the cone bound Theta (degrees) that limits each pixel's kernel (Eq. 4)
    int taps = 12;  // taps per side of each separable pass (a wider kernel: a stride)

    void validate() const {
        checkOption(coneDeg > 0.0f && coneDeg <= 60.0f, "fuzzy.coneDeg",
                    "in (0, 60] degrees (the fuzzy-reflection cone bound)", coneDeg);
        checkOption(taps >= 1 && taps <= 64, "fuzzy.taps", "1..64 taps per side", taps);
    }
};

}  // namespace mirage::render
