#pragma once
// Options of the reflected-scene impostors of specular objects (render/passes/impostor,
// docs/impostors.md).
#include "render/PassOptions.h"

namespace mirage::render {

struct ImpostorOptions {
    int resolution = 256;  // texels per side of each impostor and cube face
    // Secant refinement steps of the height-field search. 2: the first step removes most of the
    // hit error (docs/impostors.md) and the composite is within 0.01 dB of 4 or 8 steps.
    int refineSteps = 2;
    bool cubeMapBaseline = false;  // true: plain G-buffer cube map, looked up by direction

    void validate() const {
        checkOption(resolution >= 8 && resolution <= 2048, "impostor.resolution", "8..2048 texels",
                    resolution);
        checkOption(refineSteps >= 0 && refineSteps <= 64, "impostor.refineSteps", "0..64",
                    refineSteps);
    }
};

}  // namespace mirage::render
