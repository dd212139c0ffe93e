// The fuzzy-reflection pass's knobs (render/PassKnob.h).
#include <fmt/format.h>

#include "render/PassKnob.h"

namespace mirage::render {

std::vector<PassKnob> fuzzyKnobs() {
    std::vector<PassKnob> k{
        onOffKnob(
            "fuzzy",
            "on: the fuzzy-reflection filter over rough metals' mirror reflections; off: rough "
            "metals reflect sharply (their roughness ignored)",
            [](RendererOptions& o) -> bool& { return o.fuzzy.enabled; }, {"on"}),
        PassKnob{"fuzzy_cone",
                 "the fuzzy filter's cone bound Theta in degrees (0 < Theta <= 60)",
                 {"20"},
                 {},
                 [](RendererOptions& o, const std::string& v) {
                     o.fuzzy.coneDeg = float(parseKnobNumber("fuzzy_cone", v, 0.0, 60.0, true));
                 },
                 [](const RendererOptions& o) { return fmt::format("{:g}", o.fuzzy.coneDeg); }},
        intKnob("fuzzy_taps", "taps per side of each separable fuzzy-filter pass (1..64)",
                [](RendererOptions& o) -> int& { return o.fuzzy.taps; }, 1, 64, {"12"}),
    };
    return k;
}

}  // namespace mirage::render
