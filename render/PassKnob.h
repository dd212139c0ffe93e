#pragma once
// A pass's user-facing settings (Falcor's per-pass Properties): each knob names one setting of
// the pass's options struct as `mirage bench --knob`, the governor and the docs spell it
// ("caustic_map=512"), says which values it takes, and sets and reads it on RendererOptions.
// A pass folder declares its knobs beside its options (render/passes/<pass>/<Pass>Knobs.cpp);
// passKnobs() collects them from the pass list (render/PassList.cpp: one line per pass names its
// factory and its knobs).
#include <functional>
#include <string>
#include <vector>

#include "render/FrameContext.h"

namespace mirage::render {

struct PassKnob {
    std::string name, help;
    // The values `mirage bench` sweeps by default (full grid, then --quick); empty: the value
    // read() gives on RendererOptions{} alone. `quick` empty: the same as `full`.
    std::vector<std::string> full, quick;
    // Sets the value; throws mirage::Error naming the knob and the values it takes.
    std::function<void(RendererOptions&, const std::string&)> apply;
    // The knob's value in `options`, spelled as apply() takes it.
    std::function<std::string(const RendererOptions&)> read;
    // True when the setting changes only what a pass reads while it executes (a uniform, a shader
    // variant built on first use, how often it refreshes), never a texture's size or the plan:
    // the frame-time governor may change it from one frame to the next (render/governor).
    bool governed = false;

    // The values the bench sweeps by default.
    std::vector<std::string> sweep(bool quickGrid) const;
};

// Every pass's knobs, in the pass list's order (render/PassList.cpp); names are unique.
const std::vector<PassKnob>& passKnobs();
// The knob named `name`, or nullptr.
const PassKnob* findPassKnob(const std::string& name);

// The parse helpers every knob uses: each throws mirage::Error
// "knob 'NAME': 'VALUE' is not ..." naming the values the knob takes.
int parseKnobInt(const std::string& knob, const std::string& v, int lo, int hi);
// A decimal number in [lo, hi] (`loOpen`: lo itself excluded); `unit` names it in the error
// ("a number of cm").
double parseKnobNumber(const std::string& knob, const std::string& v, double lo, double hi,
                       bool loOpen = false, const char* unit = "a number");
bool parseKnobOnOff(const std::string& knob, const std::string& v);
// The index of `v` in `choices`.
size_t parseKnobChoice(const std::string& knob, const std::string& v,
                       const std::vector<std::string>& choices);
std::string knobOnOff(bool b);

// Knob builders for the common kinds; `field` returns the option the knob sets.
PassKnob onOffKnob(std::string name, std::string help, bool& (*field)(RendererOptions&),
                   std::vector<std::string> full = {});
PassKnob intKnob(std::string name, std::string help, int& (*field)(RendererOptions&), int lo,
                 int hi, std::vector<std::string> full = {}, std::vector<std::string> quick = {});
// An int that takes only the listed values (e.g. 1, 4 or 16).
PassKnob intChoiceKnob(std::string name, std::string help, int& (*field)(RendererOptions&),
                       std::vector<int> values, std::vector<std::string> full = {});
// `k` with governed = true.
PassKnob governedKnob(PassKnob k);
// A bool spelled by two names: `yes` sets it, `no` clears it.
PassKnob choiceKnob(std::string name, std::string help, bool& (*field)(RendererOptions&),
                    std::string yes, std::string no, std::vector<std::string> full = {});

}  // namespace mirage::render
