// The anti-aliasing pass's knobs (render/PassKnob.h).
#include "render/PassKnob.h"

namespace mirage::render {

std::vector<PassKnob> antialiasKnobs() {
    std::vector<PassKnob> k{
        PassKnob{"aa",
                 "anti-aliasing of what the renderer adds: morphological (the aa pass, an "
                 "edge-directed filter of the renderer's contribution) or off",
                 {},
                 {},
                 [](RendererOptions& o, const std::string& v) {
                     o.aa.enabled = parseKnobChoice("aa", v, {"off", "morphological"}) == 1;
                 },
                 [](const RendererOptions& o) {
                     return std::string(o.aa.enabled ? "morphological" : "off");
                 }},
    };
    return k;
}

}  // namespace mirage::render
