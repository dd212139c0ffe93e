// The translucency pass's knobs (render/PassKnob.h).
#include "render/PassKnob.h"

namespace mirage::render {

std::vector<PassKnob> translucencyKnobs() {
    std::vector<PassKnob> k{
        onOffKnob(
            "translucent_shadows",
            "on: a translucent object lets light through in the shadow maps (its optical "
            "thickness along the light's ray, coloured by its medium); off: it is opaque there",
            [](RendererOptions& o) -> bool& { return o.translucency.shadows; }, {"on"}),
        intKnob("vnm_resolution",
                "voxels along a translucent object's longest side in its voxel number map (2..512; "
                "the LUT grows with the 4th power)",
                [](RendererOptions& o) -> int& { return o.translucency.vnmResolution; }, 2, 512,
                {"16"}),
        choiceKnob("vnm_kernel",
                   "how light spreads between a translucent object's surface voxels: diffusion "
                   "(e^{-k tau}, k = min(1, sqrt(3 (1 - albedo))) per channel) or extinction (the "
                   "seed's e^{-tau})",
                   [](RendererOptions& o) -> bool& { return o.translucency.diffusionKernel; },
                   "diffusion", "extinction", {"extinction"}),
        choiceKnob(
            "vnm_surface",
            "where a surface voxel's normal and area come from: mesh (the object's triangles) "
            "or occupancy (the empty voxels around it and its exposed faces)",
            [](RendererOptions& o) -> bool& { return o.translucency.meshSurface; }, "mesh",
            "occupancy", {"occupancy"}),
        choiceKnob(
            "vnm_albedo",
            "the share of a translucent object's scattered light that leaves it: walks (measured "
            "by random walks through its voxels) or hapke (a thick half-space's albedo)",
            [](RendererOptions& o) -> bool& { return o.translucency.measuredAlbedo; }, "walks",
            "hapke", {"hapke"}),
        choiceKnob(
            "vnm_lookup",
            "a translucent pixel's radiance: smooth (each voxel's near field normalised, the "
            "surface voxels within 1.5 voxels blended) or nearest (the nearest voxel alone)",
            [](RendererOptions& o) -> bool& { return o.translucency.smoothLookup; }, "smooth",
            "nearest", {"smooth"}),
        onOffKnob("vnm_see_through",
                  "on: a translucent pixel shows the footage behind its object through the chord "
                  "the camera ray crosses (e^{-tau} from the voxel number map); off: it is opaque",
                  [](RendererOptions& o) -> bool& { return o.translucency.seeThrough; }, {"on"}),
        onOffKnob("vnm_reflection",
                  "on: a translucent object's boundary reflects (Fresnel) what the mirror ray "
                  "meets on screen (footage and differential light), else the environment; off: "
                  "no reflection",
                  [](RendererOptions& o) -> bool& { return o.translucency.surfaceReflection; },
                  {"on"}),
    };
    return k;
}

}  // namespace mirage::render
