// The VPL pass's knobs (render/PassKnob.h).
#include "render/PassKnob.h"

namespace mirage::render {

std::vector<PassKnob> vplKnobs() {
    std::vector<PassKnob> k{
        intKnob("vpls", "virtual point lights per frame (RendererOptions::vpl.count)",
                [](RendererOptions& o) -> int& { return o.vpl.count; }, 0, 16384,
                {"64", "256", "1024"}, {"64", "256"}),
        onOffKnob("refl_refr_vpls",
                  "on: a VPL on a mirror or glass follows the reflected / refracted photon to its "
                  "receiver (spot lights with caustics); off: it stays dark on the object",
                  [](RendererOptions& o) -> bool& { return o.vpl.throughSpecular; }, {"on"}),
        onOffKnob("vpl_rotate",
                  "on: each frame's VPLs from the Hammersley set shifted by a per-frame offset "
                  "(averaged by the GI filter's temporal smoothing; VPLs and ISMs redone every "
                  "frame); off: the same VPLs every frame",
                  [](RendererOptions& o) -> bool& { return o.vpl.temporalRotation; }),
    };
    return k;
}

}  // namespace mirage::render
