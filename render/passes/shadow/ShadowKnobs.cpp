// The shadow pass's knobs (render/PassKnob.h).
#include "render/PassKnob.h"

namespace mirage::render {

std::vector<PassKnob> shadowKnobs() {
    std::vector<PassKnob> k{
        PassKnob{"shadow_filter",
                 "pcf: shadow maps looked up with percentage-closer filtering over 4x4 texels "
                 "(straight shadow edges); off: the 2x2 bilinear lookup (1-texel stair steps)",
                 {},
                 {},
                 [](RendererOptions& o, const std::string& v) {
                     o.shadow.filter = parseKnobChoice("shadow_filter", v, {"off", "pcf"}) == 1
                                           ? ShadowFilter::Pcf
                                           : ShadowFilter::Bilinear;
                 },
                 [](const RendererOptions& o) {
                     return std::string(shadowFilterName(o.shadow.filter));
                 }},
        intKnob(
            "shadow_map", "texels per side of each shadow-map layer (occluder distance)",
            [](RendererOptions& o) -> int& { return o.shadow.mapSize; }, 16, 4096),
        intKnob(
            "shadow_rsm",
            "texels per side of each reflective-shadow-map layer (the VPLs' source; its own "
            "raster when it differs from shadow_map)",
            [](RendererOptions& o) -> int& { return o.shadow.rsmSize; }, 16, 4096),
        onOffKnob(
            "shadow_focus",
            "on: the virtual occluders in a real light's cone get a shadow map of their own, "
            "fitted to them (fine shadow edges where the virtual objects' shadows fall); off: one "
            "map of every occluder over the light's whole frustum",
            [](RendererOptions& o) -> bool& { return o.shadow.focus; }, {"on"}),
        onOffKnob(
            "shadow_footprint",
            "on: the focused maps filter each camera pixel's shadow over the pixel's footprint "
            "in the map; off: over a 2-texel box, whatever the pixel covers",
            [](RendererOptions& o) -> bool& { return o.shadow.pixelFootprint; }, {"on"}),
        onOffKnob(
            "glass_shadows",
            "on: glass transmits (tints) the light in the shadow maps of lights without caustics; "
            "off: glass is opaque there",
            [](RendererOptions& o) -> bool& { return o.shadow.glass; }, {"on"}),
    };
    return k;
}

}  // namespace mirage::render
