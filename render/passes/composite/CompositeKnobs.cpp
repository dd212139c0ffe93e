// The composite pass's knobs (render/PassKnob.h).
#include "render/PassKnob.h"

namespace mirage::render {

std::vector<PassKnob> compositeKnobs() {
    std::vector<PassKnob> k{
        onOffKnob(
            "virtual",
            "on: composite the virtual objects; off: the composite is the footage unchanged (a "
            "sanity point: it must score as the footage-only row, and any configuration that does "
            "not beat that row is broken)",
            [](RendererOptions& o) -> bool& { return o.composite.showVirtual; }, {"on"}),
    };
    return k;
}

}  // namespace mirage::render
