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
    };
    return k;
}

}  // namespace mirage::render
