#pragma once
// The real-time renderer's passes, in frame order, each with its knobs: one line per pass in
// render/PassList.cpp. A pass folder defines its factory (`makeGrainPass`: how the renderer
// constructs the pass) and, where it has settings, its knobs (`grainKnobs`, render/PassKnob.h);
// the line names both, so the central list never includes a pass's header.
#include <memory>
#include <vector>

#include "core/scene/Scene.h"
#include "render/GpuScene.h"
#include "render/PassKnob.h"
#include "render/RenderPass.h"

namespace mirage::render {

// What a pass is constructed from. Every reference outlives the pass (the Renderer owns them).
struct PassInit {
    const Scene& scene;              // as loaded (CPU side: materials, media, lights)
    const GpuScene& gpuScene;        // the scene on the GPU
    const RendererOptions& options;  // the renderer's options, validated
};

using PassFactory = std::unique_ptr<RenderPass> (*)(const PassInit&);
using PassKnobList = std::vector<PassKnob> (*)();

struct RegisteredPass {
    const char* factoryName;  // "makeGrainPass": for errors and tests
    PassFactory make;
    PassKnobList knobs;  // empty for a pass with no knobs of its own (or whose folder's knobs
                         // are on another of the folder's passes)
};

// Every pass, in the order the frame runs them.
const std::vector<RegisteredPass>& registeredPasses();

}  // namespace mirage::render
