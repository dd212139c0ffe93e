// The registry of pass knobs: one line per pass folder that declares knobs. A pass's knobs live
// in its folder (render/passes/<pass>/<Pass>Knobs.cpp, a function `<pass>Knobs()`); registering
// them is adding its line here. The order is the order `mirage bench` lists knobs a report does
// not place (render/evaluation/BenchKnobs.cpp) and the governor's (render/governor).
#include <set>

#include <fmt/format.h>

#include "core/Error.h"
#include "render/PassKnob.h"

// X(function): one line per pass.
#define MIRAGE_PASS_KNOBS(X) \
    X(specularKnobs)         \
    X(impostorKnobs)         \
    X(causticKnobs)          \
    X(vplKnobs)              \
    X(indirectKnobs)         \
    X(shadowKnobs)           \
    X(compositeKnobs)        \
    X(directKnobs)           \
    X(fuzzyKnobs)            \
    X(roughKnobs)            \
    X(translucencyKnobs)     \
    X(environmentKnobs)      \
    X(exposureKnobs)         \
    X(antialiasKnobs)        \
    X(grainKnobs)

namespace mirage::render {

#define MIRAGE_DECLARE_PASS_KNOBS(fn) std::vector<PassKnob> fn();
MIRAGE_PASS_KNOBS(MIRAGE_DECLARE_PASS_KNOBS)
#undef MIRAGE_DECLARE_PASS_KNOBS

const std::vector<PassKnob>& passKnobs() {
    static const std::vector<PassKnob> knobs = [] {
        std::vector<PassKnob> all;
#define MIRAGE_COLLECT_PASS_KNOBS(fn) \
    for (PassKnob & k : fn()) all.push_back(std::move(k));
        MIRAGE_PASS_KNOBS(MIRAGE_COLLECT_PASS_KNOBS)
#undef MIRAGE_COLLECT_PASS_KNOBS
        std::set<std::string> names;
        for (const PassKnob& k : all)
            if (!names.insert(k.name).second)
                throw Error(fmt::format("two passes declare the knob '{}'", k.name));
        return all;
    }();
    return knobs;
}

}  // namespace mirage::render
