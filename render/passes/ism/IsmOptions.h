#pragma once
// Options of the imperfect shadow maps (render/passes/ism).
#include "render/PassOptions.h"

namespace mirage::render {

struct IsmOptions {
    int tileSize = 64;        // texels per side of one VPL's imperfect shadow map
    int pointsPerVpl = 1024;  // surface points splatted into each VPL's ISM
    // Pull-push hole filling of each tile after the splats (ism_pullpush.comp; Ritschel et al.
    // 2008): an empty texel whose parent in the tile's 2x2 pyramid is covered at least
    // pullPushCoverage takes the parent's depth.
    bool pullPush = false;
    float pullPushCoverage = 0.5f;

    void validate() const {
        checkOption(tileSize >= 8 && tileSize <= 256, "ism.tileSize", "8..256", tileSize);
        checkOption(pointsPerVpl >= 1 && pointsPerVpl <= (1 << 20), "ism.pointsPerVpl",
                    "1..1048576", pointsPerVpl);
        checkOption(pullPushCoverage > 0.0f && pullPushCoverage <= 1.0f, "ism.pullPushCoverage",
                    "in (0, 1]", pullPushCoverage);
    }
};

}  // namespace mirage::render
