#pragma once
// The renderer options a frame-time governor may change from one frame to the next without
// building a new renderer: each changes only what a pass reads when it executes (a uniform, a
// shader variant built on first use, how often a pass refreshes), never a texture's size or the
// renderer's plan of lights and VPLs. They are the pass knobs that declare themselves governed
// (render/PassKnob.h), set and read through those knobs, so they carry the names of their
// `mirage bench` knobs (docs/bench.md) and a speed-vs-error table written by `mirage bench` is
// read by the governor column for column.
#include <map>
#include <string>
#include <vector>

#include "render/FrameContext.h"

namespace mirage::render {

// One quality setting: knob name -> value as `mirage bench` spells it ("specular_resolution" ->
// "half"). A knob left out keeps the value the renderer was built with.
using QualitySetting = std::map<std::string, std::string>;

// The knobs the governor may set, in the order reports list them (registration order).
const std::vector<std::string>& governedKnobNames();
bool isGovernedKnob(const std::string& name);

// Sets `setting`'s knobs in `options`. Throws mirage::Error naming the knob and the values it
// takes for an unknown knob or a bad value.
void applyQualitySetting(const QualitySetting& setting, RendererOptions& options);

// Copies the governed knobs' options from `from` into `to`, leaving every other option of `to`.
void copyGovernedOptions(const RendererOptions& from, RendererOptions& to);

// "caustic_refresh=2 specular_resolution=half" (knobs in governedKnobNames() order; "defaults"
// for an empty setting).
std::string describeQualitySetting(const QualitySetting& setting);

}  // namespace mirage::render
