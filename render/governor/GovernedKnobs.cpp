#include "render/governor/GovernedKnobs.h"

#include <fmt/format.h>

#include "core/Error.h"
#include "render/PassKnob.h"

namespace mirage::render {
namespace {

// The pass knobs that declare themselves governed (PassKnob::governed), in registration order.
const std::vector<const PassKnob*>& governedKnobs() {
    static const std::vector<const PassKnob*> k = [] {
        std::vector<const PassKnob*> g;
        for (const PassKnob& p : passKnobs())
            if (p.governed) g.push_back(&p);
        return g;
    }();
    return k;
}

const PassKnob* findGoverned(const std::string& name) {
    for (const PassKnob* k : governedKnobs())
        if (name == k->name) return k;
    return nullptr;
}

}  // namespace

const std::vector<std::string>& governedKnobNames() {
    static const std::vector<std::string> names = [] {
        std::vector<std::string> n;
        for (const PassKnob* k : governedKnobs()) n.push_back(k->name);
        return n;
    }();
    return names;
}

bool isGovernedKnob(const std::string& name) {
    return findGoverned(name) != nullptr;
}

void applyQualitySetting(const QualitySetting& setting, RendererOptions& options) {
    for (const auto& [name, value] : setting) {
        const PassKnob* k = findGoverned(name);
        if (!k)
            throw Error(
                fmt::format("quality knob '{}' cannot change while the renderer runs; "
                            "the knobs that can: {}",
                            name, fmt::join(governedKnobNames(), ", ")));
        k->apply(options, value);
    }
}

void copyGovernedOptions(const RendererOptions& from, RendererOptions& to) {
    // read() then apply() is the identity on a knob's value (tests/render/PassKnob_test.cpp).
    for (const PassKnob* k : governedKnobs()) k->apply(to, k->read(from));
}

std::string describeQualitySetting(const QualitySetting& setting) {
    std::string s;
    for (const std::string& name : governedKnobNames()) {
        const auto it = setting.find(name);
        if (it == setting.end()) continue;
        s += (s.empty() ? "" : " ") + name + "=" + it->second;
    }
    return s.empty() ? "defaults" : s;
}

}  // namespace mirage::render
