#pragma once
// Options of the imperfect shadow maps (render/passes/ism).
#include "render/PassOptions.h"

namespace mirage::render {

struct IsmOptions {
    int tileSize = 64;        // texels per side of one VPL's imperfect shadow map
    int pointsPerVpl = 1024;  // surface points splatted into each VPL's ISM

    void validate() const {
        checkOption(tileSize >= 8 && tileSize <= 256, "ism.tileSize", "8..256", tileSize);
        checkOption(pointsPerVpl >= 1 && pointsPerVpl <= (1 << 20), "ism.pointsPerVpl",
                    "1..1048576", pointsPerVpl);
    }
};

}  // namespace mirage::render
