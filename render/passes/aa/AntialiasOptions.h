#pragma once
// Options of the anti-aliasing of what the renderer adds to the footage (render/passes/aa,
// docs/camera-matching.md "Anti-aliasing").
#include "render/PassOptions.h"

namespace mirage::render {

struct AntialiasOptions {
    // The morphological filter of the renderer's contribution (antialias.frag): the virtual
    // objects' silhouettes are otherwise stair-stepped next to footage whose optics anti-alias
    // every edge (docs/results.md, "Anti-aliasing": the edge pixels' error against the ground
    // truth with and without). Off in the renderer's defaults because it costs ~20 % of the
    // frame on llvmpipe, and it is not yet reproducible between a live session and the replay of
    // its recording (it filters the footage's JPEG differences too); the bench knob `aa` and the
    // live HUD switch it on. false: the composite as the differential rendering leaves it.
    bool enabled = false;
    // An edge is filtered where the local contrast of the composite's perceptual luma (sqrt of
    // linear luminance, 0..1) exceeds max(edgeThresholdMin, edgeThreshold x the local maximum):
    // lower finds fainter edges (a shadow's on dark wood), higher leaves more of them aliased.
    float edgeThreshold = 0.063f;
    float edgeThresholdMin = 0.0156f;
    // Share of the blur of single-pixel features (thin slivers, a lone stair step): 0 keeps them
    // sharp, 1 blurs them fully into their 3x3 neighbourhood.
    float subpixel = 0.75f;
    // Steps of the search along an edge for its ends (each step 1 to 8 pixels): a longer search
    // spreads a nearly horizontal or vertical edge's blend over its whole stair step.
    int searchSteps = 10;
    // A pixel counts as changed by the renderer where the composite differs from the footage by
    // more than this (linear camera units, any channel). Only pixels within one pixel of a
    // changed one are filtered; every other pixel keeps the composite's value bit for bit.
    float changeEpsilon = 1e-4f;

    void validate() const {
        checkOption(edgeThreshold >= 0.0f && edgeThreshold <= 1.0f, "aa.edgeThreshold", "in [0, 1]",
                    edgeThreshold);
        checkOption(edgeThresholdMin >= 0.0f && edgeThresholdMin <= 1.0f, "aa.edgeThresholdMin",
                    "in [0, 1]", edgeThresholdMin);
        checkOption(subpixel >= 0.0f && subpixel <= 1.0f, "aa.subpixel", "in [0, 1]", subpixel);
        checkOption(searchSteps >= 1 && searchSteps <= 12, "aa.searchSteps", "1..12", searchSteps);
        checkOption(changeEpsilon >= 0.0f && changeEpsilon <= 1.0f, "aa.changeEpsilon",
                    "in [0, 1] (linear camera units)", changeEpsilon);
    }
};

}  // namespace mirage::render
