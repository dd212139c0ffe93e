#pragma once
// The renderer's effects a user can switch off: `mirage live` (HUD checkboxes and --off) and
// `mirage replay` (--off). Each is named as the `mirage bench` knob that switches it
// (docs/bench.md), so that a frame seen live can be replayed and benchmarked the same way.
// Switching an effect off removes its passes from the frame graph (the report says why they did
// not run); it never changes what the scene holds.
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "core/Error.h"
#include "render/FrameContext.h"

namespace mirage::app {

struct EffectSwitch {
    const char* name;                         // as the bench knob
    const char* label;                        // as the HUD shows it
    bool& (*flag)(render::RendererOptions&);  // the option that switches it, in its pass's struct
};

// `mirage live` and `mirage replay` start with every effect on, including exposure, noise and
// vignetting matching, which the renderer's defaults leave off (a fixed exposure: the renderer as a
// model, for tests).
inline constexpr EffectSwitch kEffectSwitches[] = {
    {"caustics", "caustics", [](render::RendererOptions& o) -> bool& { return o.caustic.enabled; }},
    {"caustic_temporal", "caustic smoothing",
     [](render::RendererOptions& o) -> bool& { return o.caustic.temporal; }},
    {"specular_temporal", "mirror/glass light smoothing",
     [](render::RendererOptions& o) -> bool& { return o.specular.temporal; }},
    {"glass_shadows", "shadows through glass",
     [](render::RendererOptions& o) -> bool& { return o.shadow.glass; }},
    {"refl_refr_vpls", "VPLs through mirror/glass",
     [](render::RendererOptions& o) -> bool& { return o.vpl.throughSpecular; }},
    {"specular_vpls", "VPLs in reflections",
     [](render::RendererOptions& o) -> bool& { return o.specular.vpls; }},
    {"fuzzy", "fuzzy reflections",
     [](render::RendererOptions& o) -> bool& { return o.fuzzy.enabled; }},
    {"rough_highlight", "highlights on rough mirror/glass",
     [](render::RendererOptions& o) -> bool& { return o.direct.roughHighlight; }},
    {"rough_transmission", "lights through rough glass",
     [](render::RendererOptions& o) -> bool& { return o.direct.roughTransmission; }},
    {"rough_photons", "rough caustics",
     [](render::RendererOptions& o) -> bool& { return o.caustic.roughLobes; }},
    {"translucency", "translucency",
     [](render::RendererOptions& o) -> bool& { return o.translucency.enabled; }},
    {"exposure_match", "exposure matching",
     [](render::RendererOptions& o) -> bool& { return o.exposureMatch.enabled; }},
    {"aa", "anti-aliasing", [](render::RendererOptions& o) -> bool& { return o.aa.enabled; }},
    {"noise_match", "noise matching",
     [](render::RendererOptions& o) -> bool& { return o.grain.noise.enabled; }},
    {"vignette_match", "vignetting matching",
     [](render::RendererOptions& o) -> bool& { return o.grain.vignette.enabled; }},
};

inline std::string effectSwitchNames() {
    std::string s;
    for (const EffectSwitch& e : kEffectSwitches)
        s += (s.empty() ? "" : ", ") + std::string(e.name);
    return s;
}

inline const EffectSwitch* findEffectSwitch(const std::string& name) {
    for (const EffectSwitch& e : kEffectSwitches)
        if (name == e.name) return &e;
    return nullptr;
}

// `--off NAME[,NAME...]`: each name checked while the arguments are parsed, before any work.
inline CLI::Validator effectSwitchName() {
    return CLI::Validator(
        [](std::string& name) -> std::string {
            if (findEffectSwitch(name)) return {};
            return "'" + name + "' is not an effect; the effects are: " + effectSwitchNames();
        },
        "EFFECT");
}

// Switches the named effects off in `options`; throws Error for a name it does not know, with
// the names it does.
inline void switchEffectsOff(const std::vector<std::string>& names,
                             render::RendererOptions& options) {
    for (const std::string& n : names) {
        const EffectSwitch* e = findEffectSwitch(n);
        if (!e)
            throw Error(fmt::format("--off: '{}' is not an effect; the effects are: {}", n,
                                    effectSwitchNames()));
        e->flag(options) = false;
    }
}

}  // namespace mirage::app
