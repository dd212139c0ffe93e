#pragma once
// Options of translucent objects (render/passes/translucency, docs/translucency.md).
#include <string>

#include "render/PassOptions.h"

namespace mirage::render {

struct TranslucencyOptions {
    // A voxel number map per translucent object (up to 8), vnmResolution voxels along its longest
    // side (the tau LUT grows with the square of the surface voxels, ~36 n^4 bytes for a cube),
    // its LUT cached in vnmCacheDir (empty: precomputed every time a renderer is created). false:
    // translucent objects are drawn as opaque surfaces of their base colour.
    bool enabled = true;
    // A translucent object lets light through in the shadow maps (Fresnel at each crossing, its
    // optical thickness along the light's ray; docs/translucency.md "Shadows"); false: it is an
    // opaque occluder.
    bool shadows = true;
    int vnmResolution = 16;
    std::string vnmCacheDir;

    void validate() const {
        checkOption(vnmResolution >= 2 && vnmResolution <= 512, "translucency.vnmResolution",
                    "2..512", vnmResolution);
    }
};

}  // namespace mirage::render
