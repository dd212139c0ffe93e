#include "render/PassKnob.h"

#include <cstdlib>

#include <fmt/format.h>

#include "core/Error.h"

namespace mirage::render {

std::vector<std::string> PassKnob::sweep(bool quickGrid) const {
    if (quickGrid && !quick.empty()) return quick;
    if (!full.empty()) return full;
    return {read(RendererOptions{})};
}

const PassKnob* findPassKnob(const std::string& name) {
    for (const PassKnob& k : passKnobs())
        if (k.name == name) return &k;
    return nullptr;
}

int parseKnobInt(const std::string& knob, const std::string& v, int lo, int hi) {
    try {
        size_t used = 0;
        const int x = std::stoi(v, &used);
        if (used == v.size() && x >= lo && x <= hi) return x;
    } catch (const std::exception&) {
    }
    throw Error(fmt::format("knob '{}': '{}' is not an integer in [{}, {}]", knob, v, lo, hi));
}

double parseKnobNumber(const std::string& knob, const std::string& v, double lo, double hi,
                       bool loOpen, const char* unit) {
    char* end = nullptr;
    const double x = std::strtod(v.c_str(), &end);
    const bool inRange = (loOpen ? x > lo : x >= lo) && x <= hi;  // false for NaN
    if (v.empty() || end != v.c_str() + v.size() || !inRange)
        throw Error(fmt::format("knob '{}': '{}' is not {} in {}{:g}, {:g}]", knob, v, unit,
                                loOpen ? "(" : "[", lo, hi));
    return x;
}

size_t parseKnobChoice(const std::string& knob, const std::string& v,
                       const std::vector<std::string>& choices) {
    for (size_t i = 0; i < choices.size(); ++i)
        if (v == choices[i]) return i;
    std::string list;
    for (size_t i = 0; i < choices.size(); ++i)
        list += (i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ") + choices[i];
    throw Error(fmt::format("knob '{}': '{}' is not {}", knob, v, list));
}

bool parseKnobOnOff(const std::string& knob, const std::string& v) {
    return parseKnobChoice(knob, v, {"on", "off"}) == 0;
}

std::string knobOnOff(bool b) {
    return b ? "on" : "off";
}

PassKnob onOffKnob(std::string name, std::string help, bool& (*field)(RendererOptions&),
                   std::vector<std::string> full) {
    const std::string n = name;
    return {
        std::move(name),
        std::move(help),
        std::move(full),
        {},
        [n, field](RendererOptions& o, const std::string& v) { field(o) = parseKnobOnOff(n, v); },
        [field](const RendererOptions& o) {
            RendererOptions copy = o;  // `field` gives write access
            return knobOnOff(field(copy));
        }};
}

PassKnob intKnob(std::string name, std::string help, int& (*field)(RendererOptions&), int lo,
                 int hi, std::vector<std::string> full, std::vector<std::string> quick) {
    const std::string n = name;
    return {std::move(name),
            std::move(help),
            std::move(full),
            std::move(quick),
            [n, field, lo, hi](RendererOptions& o, const std::string& v) {
                field(o) = parseKnobInt(n, v, lo, hi);
            },
            [field](const RendererOptions& o) {
                RendererOptions copy = o;
                return std::to_string(field(copy));
            }};
}

PassKnob intChoiceKnob(std::string name, std::string help, int& (*field)(RendererOptions&),
                       std::vector<int> values, std::vector<std::string> full) {
    const std::string n = name;
    std::vector<std::string> spelled;
    for (int v : values) spelled.push_back(std::to_string(v));
    return {std::move(name),
            std::move(help),
            std::move(full),
            {},
            [n, field, values, spelled](RendererOptions& o, const std::string& v) {
                field(o) = values[parseKnobChoice(n, v, spelled)];
            },
            [field](const RendererOptions& o) {
                RendererOptions copy = o;
                return std::to_string(field(copy));
            }};
}

PassKnob governedKnob(PassKnob k) {
    k.governed = true;
    return k;
}

PassKnob choiceKnob(std::string name, std::string help, bool& (*field)(RendererOptions&),
                    std::string yes, std::string no, std::vector<std::string> full) {
    const std::string n = name;
    return {std::move(name),
            std::move(help),
            std::move(full),
            {},
            [n, field, yes, no](RendererOptions& o, const std::string& v) {
                field(o) = parseKnobChoice(n, v, {yes, no}) == 0;
            },
            [field, yes, no](const RendererOptions& o) {
                RendererOptions copy = o;
                return field(copy) ? yes : no;
            }};
}

}  // namespace mirage::render
