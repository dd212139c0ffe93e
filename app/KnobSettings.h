#pragma once
// `--set KNOB=VALUE` of `mirage replay` and `mirage live`: any pass knob (`mirage bench
// --list-knobs`, render/PassKnob.h) set on the renderer's options, so a setting a pass declares
// in its own folder reaches the user without a flag of its own.
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "core/Error.h"
#include "render/FrameContext.h"
#include "render/PassKnob.h"

namespace mirage::app {

// Sets each "KNOB=VALUE" on `options`, in order; throws Error naming the setting and what the
// knob takes (an unknown knob: the knobs there are).
inline void applyKnobSettings(const std::vector<std::string>& settings,
                              render::RendererOptions& options) {
    for (const std::string& s : settings) {
        const size_t eq = s.find('=');
        if (eq == std::string::npos || eq == 0)
            throw Error(fmt::format("--set '{}': write KNOB=VALUE, e.g. --set caustic_map=512", s));
        const std::string name = s.substr(0, eq);
        const render::PassKnob* k = render::findPassKnob(name);
        if (!k) {
            std::string names;
            for (const render::PassKnob& p : render::passKnobs())
                names += (names.empty() ? "" : ", ") + p.name;
            throw Error(fmt::format("--set '{}': no knob '{}'; the knobs are: {}", s, name, names));
        }
        k->apply(options, s.substr(eq + 1));
    }
}

// `--set KNOB=VALUE`: checked on the defaults while the arguments are parsed, before any work.
inline CLI::Validator knobSetting() {
    return CLI::Validator(
        [](std::string& s) -> std::string {
            try {
                render::RendererOptions o;
                applyKnobSettings({s}, o);
                o.validate();
            } catch (const Error& e) {
                return e.what();
            }
            return {};
        },
        "KNOB=VALUE");
}

}  // namespace mirage::app
