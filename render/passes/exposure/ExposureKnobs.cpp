// The exposure-matching pass's knobs (render/PassKnob.h).
#include "render/PassKnob.h"

namespace mirage::render {

std::vector<PassKnob> exposureKnobs() {
    std::vector<PassKnob> k{
        onOffKnob(
            "exposure_match",
            "on: the exposure and white balance estimated every frame from the footage against the "
            "rendered real surfaces, applied to what the renderer adds; off: the fixed --exposure",
            [](RendererOptions& o) -> bool& { return o.exposureMatch.enabled; }, {"off"}),
    };
    return k;
}

}  // namespace mirage::render
