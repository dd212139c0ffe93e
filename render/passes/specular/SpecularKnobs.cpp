// The specular passes' knobs (render/PassKnob.h); the governed ones change only a uniform or a
// shader variant, so the frame-time governor may set them between frames.
#include <fmt/format.h>

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
        governedKnob(PassKnob{
            "specular_vpl_stride",
            "VPL interleaving at the reflected/refracted hits: each hit sums every N-th VPL (x N) "
            "over an N-pixel tile: 1 (all), 4 (2x2) or 16 (4x4)",
            {},
            {},
            [](RendererOptions& o, const std::string& v) {
                const int strides[] = {1, 4, 16};
                o.specular.vplStride =
                    strides[parseKnobChoice("specular_vpl_stride", v, {"1", "4", "16"})];
            },
            [](const RendererOptions& o) { return std::to_string(o.specular.vplStride); }}),
        governedKnob(intKnob(
            "refraction_steps",
            "march steps of the refracted ray through the back-face buffer (the exit point; also "
            "the caustic photons')",
            [](RendererOptions& o) -> int& { return o.specular.refractionMarchSteps; }, 2, 128,
            {"16"})),
        governedKnob(PassKnob{
            "specular_refresh",
            "frames over which the reflected / refracted hits' light is refreshed (1, 2 or 4): "
            "each frame shades one phase of 8x8-pixel tiles, the others take last frame's light "
            "where it was lit at this frame's hits",
            {},
            {},
            [](RendererOptions& o, const std::string& v) {
                const int frames[] = {1, 2, 4};
                o.specular.refreshInterval =
                    frames[parseKnobChoice("specular_refresh", v, {"1", "2", "4"})];
            },
            [](const RendererOptions& o) { return std::to_string(o.specular.refreshInterval); }}),
        onOffKnob(
            "specular_temporal",
            "on: the light of the reflected / refracted hits (L'_rv, L'_r) smoothed over frames, "
            "history rejected where a hit moved; off: every frame's stands alone",
            [](RendererOptions& o) -> bool& { return o.specular.temporal; }, {"on"}),
    };
    return k;
}

}  // namespace mirage::render
