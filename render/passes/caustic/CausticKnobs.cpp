// The caustic passes' knobs (render/PassKnob.h); the gather cap (a loop bound) and the refresh
// interval (how often the splat runs) the frame-time governor may set between frames.
// per frame.
#include <fmt/format.h>

#include "core/Error.h"
#include "render/PassKnob.h"

namespace mirage::render {

std::vector<PassKnob> causticKnobs() {
    std::vector<PassKnob> k{
        onOffKnob("caustics",
                  "on: photon G-buffers and the caustic splat for spot lights on mirror/glass",
                  [](RendererOptions& o) -> bool& { return o.caustic.enabled; }, {"on"}),
        PassKnob{"caustic_map",
                 "texels per side of each photon G-buffer (a multiple of 8)",
                 {"256"},
                 {},
                 [](RendererOptions& o, const std::string& v) {
                     const int n = parseKnobInt("caustic_map", v, 16, 2048);
                     if (n % 8 != 0)
                         throw Error(
                             fmt::format("knob 'caustic_map': '{}' is not a multiple of 8", v));
                     o.caustic.mapSize = n;
                 },
                 [](const RendererOptions& o) { return std::to_string(o.caustic.mapSize); }},
        PassKnob{"caustic_quad",
                 "photon quad radius in photon spacings on the receiver (0.25..8)",
                 {"1.5"},
                 {},
                 [](RendererOptions& o, const std::string& v) {
                     o.caustic.quadScale = float(parseKnobNumber("caustic_quad", v, 0.25, 8.0));
                 },
                 [](const RendererOptions& o) { return fmt::format("{:g}", o.caustic.quadScale); }},
        onOffKnob(
            "caustic_gather",
            "on: the photons in a world-space grid, gathered at the reflected / refracted hits "
            "(caustics seen in mirrors and through glass); off: those hits get no caustic",
            [](RendererOptions& o) -> bool& { return o.caustic.gather; }, {"on"}),
        onOffKnob("rough_photons",
                  "on: photons leaving a rough mirror, metal or glass scatter over its GGX lobe (a "
                  "soft caustic, spread reflected / refracted VPLs); off: they follow the mirror / "
                  "Snell ray (a sharp caustic)",
                  [](RendererOptions& o) -> bool& { return o.caustic.roughLobes; }, {"on"}),
        PassKnob{
            "caustic_radius",
            "photon kernel radius cap of the caustic gather, in cm (0.1..50; grid cells are twice "
            "that)",
            {"1"},
            {},
            [](RendererOptions& o, const std::string& v) {
                o.caustic.gatherRadius =
                    0.01f *
                    float(parseKnobNumber("caustic_radius", v, 0.1, 50.0, false, "a number of cm"));
            },
            [](const RendererOptions& o) {
                return fmt::format("{:g}", 100.0f * o.caustic.gatherRadius);
            }},
        governedKnob(intKnob(
            "caustic_gather_cap",
            "photons the caustic gather reads per grid bucket, 0 = all (a fuller bucket is read "
            "by its finest stratified subsample of the photon map within the cap, weighted by "
            "count / read)",
            [](RendererOptions& o) -> int& { return o.caustic.gatherCap; }, 0, 1 << 20)),
        governedKnob(intKnob(
            "caustic_refresh",
            "frames between two splats of the caustic photons (1..8); in the frames between, last "
            "frame's caustic reprojected by the receivers' positions",
            [](RendererOptions& o) -> int& { return o.caustic.refreshInterval; }, 1, 8)),
        onOffKnob(
            "caustic_temporal",
            "on: the caustic buffer smoothed over frames (reprojected history, the GI filter's "
            "reset rules); off: every frame's caustic stands alone",
            [](RendererOptions& o) -> bool& { return o.caustic.temporal; }, {"on"}),
    };
    return k;
}

}  // namespace mirage::render
