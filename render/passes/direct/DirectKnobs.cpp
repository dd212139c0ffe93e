// The direct-light pass's knobs (render/PassKnob.h).
#include "render/PassKnob.h"

namespace mirage::render {

std::vector<PassKnob> directKnobs() {
    std::vector<PassKnob> k{
        onOffKnob(
            "rough_highlight",
            "on: rough mirrors, metals and glass show the punctual lights' GGX highlight; off: "
            "their light comes from the mirror / refracted ray alone (no highlight)",
            [](RendererOptions& o) -> bool& { return o.direct.roughHighlight; }, {"on"}),
        onOffKnob("rough_transmission",
                  "on: rough glass also lets the punctual lights through towards the eye, "
                  "scattered by its rough faces where their light enters it (with "
                  "rough_highlight); off: only its reflection of them",
                  [](RendererOptions& o) -> bool& { return o.direct.roughTransmission; }, {"on"}),
    };
    return k;
}

}  // namespace mirage::render
