#pragma once
// A render pass of the real-time renderer: declares the frame resources it reads and writes,
// decides per frame whether the scene needs it (and says why), allocates its targets in
// resize(), and records GL work in execute() without allocating. Shaders live beside the pass
// (render/passes/<pass>/) and are embedded at build time.
#include <string>
#include <string_view>
#include <vector>

#include "render/FrameContext.h"

namespace mirage::render {

// A program of fullscreen.vert + the fragment shader at `fragmentPath` (relative to render/),
// with `defines` inserted after #version (shader variants).
gl::Program fullscreenProgram(std::string_view label, std::string_view fragmentPath,
                              std::string_view defines = {});

struct PassDecision {
    bool run = true;
    std::string reason;  // e.g. "2 lights have casters in their cone" / "no virtual object lit"
};

class RenderPass {
public:
    virtual ~RenderPass() = default;
    virtual const char* name() const = 0;
    virtual std::vector<Resource> reads() const = 0;
    virtual std::vector<Resource> writes() const = 0;
    virtual PassDecision decide(const FrameContext& ctx) const = 0;
    // (Re)allocates targets for ctx's canvas / plan. Called before every frame the pass runs:
    // it must return at once unless a size changed (reallocating costs page faults on every
    // target, and would drop state such as the temporal history).
    virtual void resize(const FrameContext& ctx) = 0;
    virtual void execute(FrameContext& ctx) = 0;

    // True for passes whose output depends only on the scene and the frame plan (lights, their
    // matrices, shadow layers, VPL allocation) and never on the camera: shadow maps + RSMs,
    // VPLs, imperfect shadow maps. Scenes are static, so while the plan is unchanged the renderer
    // reuses their last output (publishCached) instead of re-running them.
    virtual bool cameraIndependent() const { return false; }
    // Publishes what the last execute() wrote, unchanged (cameraIndependent passes only).
    virtual void publishCached(FrameContext&) {}
};

}  // namespace mirage::render
