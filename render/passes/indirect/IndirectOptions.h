#pragma once
// Options of the VPL gather (render/passes/indirect, docs/realtime-renderer.md).
#include <algorithm>

#include "render/PassOptions.h"

namespace mirage::render {

struct IndirectOptions {
    int interleave = 4;  // K: each pixel gathers vpl.count / K^2 VPLs
    // VPL gather at 1/scale resolution per axis, 1..4, upsampled by the geometry-aware filter; 0:
    // automatic, gatherScale(): a gather pixel every ~1/160 of the canvas width whatever the
    // resolution, so that the indirect light keeps its detail relative to the image.
    int scale = 0;
    float distanceClamp = 0.1f;  // metres: VPL distance below this is clamped (no spikes)

    // The gather scale for a canvas this wide: scale, or when 0 width / 160 in 1..4 (4 at
    // 640x480, 2 at 320x240, 1 at 160x120).
    int gatherScale(int canvasWidth) const {
        return scale > 0 ? scale : std::clamp(canvasWidth / 160, 1, 4);
    }
    void validate() const {
        checkOption(interleave >= 1 && interleave <= 8, "indirect.interleave", "1..8", interleave);
        checkOption(scale >= 0 && scale <= 4, "indirect.scale", "0 (automatic) or 1..4", scale);
    }
};

}  // namespace mirage::render
