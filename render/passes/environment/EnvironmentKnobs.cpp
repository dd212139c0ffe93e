// The environment pass's knobs (render/PassKnob.h).
#include <fmt/format.h>

#include "core/Error.h"
#include "render/PassKnob.h"

namespace mirage::render {

std::vector<PassKnob> environmentKnobs() {
    std::vector<PassKnob> k{
        PassKnob{"env_resolution",
                 "width of the environment map built from each environment-camera frame (height = "
                 "width "
                 "/ 2; with env_source=camera)",
                 {"512"},
                 {},
                 [](RendererOptions& o, const std::string& v) {
                     const int w = parseKnobInt("env_resolution", v, 16, 4096);
                     if (w % 2 != 0)
                         throw Error(fmt::format("knob 'env_resolution': '{}' is not even", v));
                     o.environment.mapWidth = w;
                 },
                 [](const RendererOptions& o) { return std::to_string(o.environment.mapWidth); }},
        intKnob(
            "env_lights",
            "lights found in each environment-camera frame placed as shadow-casting lights, taken "
            "out of the environment light (0 = none; with env_source=camera)",
            [](RendererOptions& o) -> int& { return o.environment.lights; }, 0, kMaxLights, {"0"}),
    };
    return k;
}

}  // namespace mirage::render
