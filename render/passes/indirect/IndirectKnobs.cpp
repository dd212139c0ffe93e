// The indirect-light pass's knobs (render/PassKnob.h).
#include "render/PassKnob.h"

namespace mirage::render {

std::vector<PassKnob> indirectKnobs() {
    std::vector<PassKnob> k{
        PassKnob{"indirect_scale",
                 "VPL gather at 1/N resolution per axis (1..4), or auto: width / 160 in 1..4 (4 at "
                 "640x480)",
                 {"auto", "2", "1"},
                 {"auto"},
                 [](RendererOptions& o, const std::string& v) {
                     o.indirect.scale = v == "auto" ? 0 : parseKnobInt("indirect_scale", v, 1, 4);
                 },
                 [](const RendererOptions& o) {
                     return o.indirect.scale == 0 ? std::string("auto")
                                                  : std::to_string(o.indirect.scale);
                 }},
    };
    return k;
}

}  // namespace mirage::render
