#pragma once
// Options of the shadow maps and reflective shadow maps (render/passes/shadow).
#include "render/PassOptions.h"

namespace mirage::render {

struct ShadowOptions {
    int mapSize = 512;    // texels per side of each shadow / RSM layer
    float bias = 0.001f;  // metres: constant depth bias of the shadow-map test
                          // (lighting.glsl adds 1.5 texels' footprint / cos)
    // Glass transmits light in the shadow maps (coloured, Fresnel and Beer-Lambert weighted);
    // false: glass is an opaque occluder, as mirrors are.
    bool glass = true;

    void validate() const {
        checkOption(mapSize >= 16 && mapSize <= 4096, "shadow.mapSize", "16..4096", mapSize);
        checkOption(bias >= 0.0f && bias <= 1.0f, "shadow.bias", "in [0, 1] metres", bias);
    }
};

}  // namespace mirage::render
