// The impostor pass's knobs (render/PassKnob.h); the refinement steps (a loop count of the trace)
// the frame-time governor may set between frames.
#include "render/PassKnob.h"

namespace mirage::render {

std::vector<PassKnob> impostorKnobs() {
    std::vector<PassKnob> k{
        choiceKnob(
            "specular_trace",
            "what reflected/refracted rays are traced against: impostors (Popescu et al. 2006) or "
            "cubemap (the plain G-buffer cube-map baseline)",
            [](RendererOptions& o) -> bool& { return o.impostor.cubeMapBaseline; }, "cubemap",
            "impostors", {"impostors"}),
        intKnob("impostor_resolution", "texels per side of each impostor and cube-map face",
                [](RendererOptions& o) -> int& { return o.impostor.resolution; }, 16, 2048,
                {"256"}),
        governedKnob(intKnob(
            "impostor_steps", "refinement steps of the impostor height-field search",
            [](RendererOptions& o) -> int& { return o.impostor.refineSteps; }, 0, 32, {"2"})),
    };
    return k;
}

}  // namespace mirage::render
