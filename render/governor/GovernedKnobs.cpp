#include "render/governor/GovernedKnobs.h"

#include <algorithm>
#include <functional>

#include <fmt/format.h>

#include "core/Error.h"

namespace mirage::render {
namespace {

int parseRange(const std::string& knob, const std::string& v, int lo, int hi) {
    try {
        size_t used = 0;
        const int x = std::stoi(v, &used);
        if (used == v.size() && x >= lo && x <= hi) return x;
    } catch (const std::exception&) {
    }
    throw Error(
        fmt::format("quality knob '{}': '{}' is not an integer in [{}, {}]", knob, v, lo, hi));
}

struct GovernedKnob {
    const char* name;
    std::function<void(RendererOptions&, const std::string&)> set;
    std::function<void(const RendererOptions&, RendererOptions&)> copy;
};

const std::vector<GovernedKnob>& knobs() {
    static const std::vector<GovernedKnob> k = {
        {"specular_resolution",
         [](RendererOptions& o, const std::string& v) {
             if (v != "full" && v != "half")
                 throw Error(fmt::format(
                     "quality knob 'specular_resolution': '{}' is not full or half", v));
             o.specular.halfResolution = v == "half";
         },
         [](const RendererOptions& f, RendererOptions& t) {
             t.specular.halfResolution = f.specular.halfResolution;
         }},
        {"specular_trace_resolution",
         [](RendererOptions& o, const std::string& v) {
             if (v != "full" && v != "half")
                 throw Error(fmt::format(
                     "quality knob 'specular_trace_resolution': '{}' is not full or half", v));
             o.specular.halfResolutionTrace = v == "half";
         },
         [](const RendererOptions& f, RendererOptions& t) {
             t.specular.halfResolutionTrace = f.specular.halfResolutionTrace;
         }},
        {"specular_vpl_stride",
         [](RendererOptions& o, const std::string& v) {
             const int n = parseRange("specular_vpl_stride", v, 1, 16);
             if (n != 1 && n != 4 && n != 16)
                 throw Error(
                     fmt::format("quality knob 'specular_vpl_stride': '{}' is not 1, 4 or 16", v));
             o.specular.vplStride = n;
         },
         [](const RendererOptions& f, RendererOptions& t) {
             t.specular.vplStride = f.specular.vplStride;
         }},
        {"refraction_steps",
         [](RendererOptions& o, const std::string& v) {
             o.specular.refractionMarchSteps = parseRange("refraction_steps", v, 2, 128);
         },
         [](const RendererOptions& f, RendererOptions& t) {
             t.specular.refractionMarchSteps = f.specular.refractionMarchSteps;
         }},
        {"impostor_steps",
         [](RendererOptions& o, const std::string& v) {
             o.impostor.refineSteps = parseRange("impostor_steps", v, 0, 32);
         },
         [](const RendererOptions& f, RendererOptions& t) {
             t.impostor.refineSteps = f.impostor.refineSteps;
         }},
        {"caustic_gather_cap",
         [](RendererOptions& o, const std::string& v) {
             o.caustic.gatherCap = parseRange("caustic_gather_cap", v, 0, 1 << 20);
         },
         [](const RendererOptions& f, RendererOptions& t) {
             t.caustic.gatherCap = f.caustic.gatherCap;
         }},
        {"specular_refresh",
         [](RendererOptions& o, const std::string& v) {
             const int n = parseRange("specular_refresh", v, 1, 4);
             if (n == 3)
                 throw Error(
                     fmt::format("quality knob 'specular_refresh': '{}' is not 1, 2 or 4", v));
             o.specular.refreshInterval = n;
         },
         [](const RendererOptions& f, RendererOptions& t) {
             t.specular.refreshInterval = f.specular.refreshInterval;
         }},
        {"caustic_refresh",
         [](RendererOptions& o, const std::string& v) {
             o.caustic.refreshInterval = parseRange("caustic_refresh", v, 1, 8);
         },
         [](const RendererOptions& f, RendererOptions& t) {
             t.caustic.refreshInterval = f.caustic.refreshInterval;
         }},
    };
    return k;
}

const GovernedKnob* findKnob(const std::string& name) {
    for (const GovernedKnob& k : knobs())
        if (name == k.name) return &k;
    return nullptr;
}

}  // namespace

const std::vector<std::string>& governedKnobNames() {
    static const std::vector<std::string> names = [] {
        std::vector<std::string> n;
        for (const GovernedKnob& k : knobs()) n.push_back(k.name);
        return n;
    }();
    return names;
}

bool isGovernedKnob(const std::string& name) {
    return findKnob(name) != nullptr;
}

void applyQualitySetting(const QualitySetting& setting, RendererOptions& options) {
    for (const auto& [name, value] : setting) {
        const GovernedKnob* k = findKnob(name);
        if (!k)
            throw Error(
                fmt::format("quality knob '{}' cannot change while the renderer runs; "
                            "the knobs that can: {}",
                            name, fmt::join(governedKnobNames(), ", ")));
        k->set(options, value);
    }
}

void copyGovernedOptions(const RendererOptions& from, RendererOptions& to) {
    for (const GovernedKnob& k : knobs()) k.copy(from, to);
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
