// The grain pass's knobs: noise and vignetting matching (render/PassKnob.h).
#include "render/PassKnob.h"

namespace mirage::render {

std::vector<PassKnob> grainKnobs() {
    std::vector<PassKnob> k{
        PassKnob{
            "noise_match",
            "on: the footage's noise (its level per intensity, estimated every frame) added to the "
            "pixels the renderer changed, drawn from the footage's own grain; synthesised: the "
            "same "
            "level drawn as Gaussian noise from a seed; off: they stay clean",
            {"off"},
            {},
            [](RendererOptions& o, const std::string& v) {
                const size_t i = parseKnobChoice("noise_match", v, {"off", "on", "synthesised"});
                o.grain.noise.enabled = i != 0;
                o.grain.noise.footageGrain = i == 1;
            },
            [](const RendererOptions& o) {
                const auto& n = o.grain.noise;
                return std::string(!n.enabled ? "off" : n.footageGrain ? "on" : "synthesised");
            }},
        onOffKnob(
            "vignette_match",
            "on: the camera's vignetting (estimated from the footage over frames) applied to the "
            "virtual pixels; off: none",
            [](RendererOptions& o) -> bool& { return o.grain.vignette.enabled; }, {"off"}),
    };
    return k;
}

}  // namespace mirage::render
