// The imperfect shadow maps' knobs (render/PassKnob.h).
#include "render/PassKnob.h"

namespace mirage::render {

std::vector<PassKnob> ismKnobs() {
    return {
        intKnob(
            "ism_tile", "texels per side of each VPL's imperfect shadow map (8..256)",
            [](RendererOptions& o) -> int& { return o.ism.tileSize; }, 8, 256),
        intKnob(
            "ism_points", "surface points splatted into each VPL's imperfect shadow map",
            [](RendererOptions& o) -> int& { return o.ism.pointsPerVpl; }, 1, 1 << 20),
        onOffKnob("ism_pullpush",
                  "on: the gaps between a surface's splatted points in each imperfect shadow map "
                  "filled by pull-push (Ritschel 2008); off: the splats alone",
                  [](RendererOptions& o) -> bool& { return o.ism.pullPush; }),
    };
}

}  // namespace mirage::render
