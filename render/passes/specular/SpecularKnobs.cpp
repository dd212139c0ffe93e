// The specular passes' knobs (render/PassKnob.h); the governed ones change only a uniform or a
// shader variant, so the frame-time governor may set them between frames.
#include "render/PassKnob.h"

namespace mirage::render {

std::vector<PassKnob> specularKnobs() {
    std::vector<PassKnob> k{
        governedKnob(choiceKnob(
            "specular_resolution",
            "resolution of the lighting at the reflected/refracted hits: full (every specular "
            "pixel) or half (one pixel per 2x2 block, upsampled by hit geometry)",
            [](RendererOptions& o) -> bool& { return o.specular.halfResolution; }, "half", "full")),
        governedKnob(choiceKnob(
            "specular_trace_resolution",
            "resolution of the reflected/refracted ray search (specgbuf): full (a ray pair per "
            "specular pixel) or half (one per 2x2 block, filled by primary-surface geometry)",
            [](RendererOptions& o) -> bool& { return o.specular.halfResolutionTrace; }, "half",
            "full")),
        governedKnob(intChoiceKnob(
            "specular_vpl_stride",
            "VPL interleaving at the reflected/refracted hits: each hit sums every N-th VPL (x N) "
            "over an N-pixel tile: 1 (all), 4 (2x2) or 16 (4x4)",
            [](RendererOptions& o) -> int& { return o.specular.vplStride; }, {1, 4, 16})),
        governedKnob(intKnob(
            "refraction_steps",
            "march steps of the refracted ray through the back-face buffer (the exit point; also "
            "the caustic photons')",
            [](RendererOptions& o) -> int& { return o.specular.refractionMarchSteps; }, 2, 128,
            {"16"})),
        governedKnob(intChoiceKnob(
            "specular_refresh",
            "frames over which the reflected / refracted hits' light is refreshed (1, 2 or 4): "
            "each frame shades one phase of 8x8-pixel tiles, the others take last frame's light "
            "where it was lit at this frame's hits",
            [](RendererOptions& o) -> int& { return o.specular.refreshInterval; }, {1, 2, 4})),
        governedKnob(onOffKnob(
            "second_exit",
            "on: glass's refracted path followed past the internal reflection at its back face to "
            "a second exit, whose environment light the composite adds to the pixel's L_env; off: "
            "the first exit only",
            [](RendererOptions& o) -> bool& { return o.specular.secondExit; }, {"on"})),
        onOffKnob(
            "specular_temporal",
            "on: the light of the reflected / refracted hits (L'_rv, L'_r) smoothed over frames, "
            "history rejected where a hit moved; off: every frame's stands alone",
            [](RendererOptions& o) -> bool& { return o.specular.temporal; }, {"on"}),
    };
    return k;
}

}  // namespace mirage::render
