#pragma once
// A render pass of the real-time renderer (render/FrameGraph.h): declares in setup() the named
// resources it writes and reads, states per frame the scene condition it needs (decide()),
// allocates its targets in resize(), and records GL work in execute() without allocating,
// getting other passes' textures only by name from its PassResources view. Shaders live beside
// the pass (render/passes/<pass>/) and are embedded at build time.
#include <string>
#include <string_view>
#include <vector>

#include "render/FrameContext.h"
#include "render/Resource.h"

namespace mirage::render {

class PassResources;

// A program of fullscreen.vert + the fragment shader at `fragmentPath` (relative to render/),
// with `defines` inserted after #version (shader variants).
gl::Program fullscreenProgram(std::string_view label, std::string_view fragmentPath,
                              std::string_view defines = {});
// A raster program of a vertex and a fragment shader (paths relative to render/).
gl::Program rasterProgram(std::string_view label, std::string_view vertexPath,
                          std::string_view fragmentPath, std::string_view defines = {});
// A compute program (path relative to render/).
gl::Program computeProgram(std::string_view label, std::string_view computePath,
                           std::string_view defines = {});

struct PassDecision {
    bool run = true;
    std::string reason;  // e.g. "2 lights have casters in their cone" / "no virtual object lit"
};

// One declared write / read of a pass.
struct ResourceWrite {
    Resource id;
    bool buffer = false;
    GLenum format = 0;  // GL internal format (textures)
    SizeRule size = SizeRule::Canvas;
    bool persistent = false;  // kept across frames by its pass (history, impostors)
};
struct ResourceRead {
    Resource id;
    bool optional = false;
};

// Collects a pass's declarations (FrameGraph::addPass calls RenderPass::setup with it).
class PassBuilder {
public:
    // A texture the pass writes (allocates and publishes), with its GL internal format and size
    // rule. persistent: the pass keeps it across frames (temporal history, impostors).
    void write(Resource r, GLenum format, SizeRule size, bool persistent = false);
    void writeBuffer(Resource r, SizeRule size, bool persistent = false);
    // A resource the pass reads: required (the pass is skipped when no pass writes it this
    // frame) or optional (the pass checks PassResources::has and falls back).
    void read(Resource r);
    void readOptional(Resource r);

    const std::vector<ResourceWrite>& writes() const { return writes_; }
    const std::vector<ResourceRead>& reads() const { return reads_; }

private:
    friend class FrameGraph;
    std::vector<ResourceWrite> writes_;
    std::vector<ResourceRead> reads_;
};

class RenderPass {
public:
    virtual ~RenderPass() = default;
    virtual const char* name() const = 0;
    virtual void setup(PassBuilder& b) const = 0;
    // The scene condition this pass needs this frame, and why (e.g. "no mirror or glass object
    // in view"). What its inputs need is the graph's business, not the pass's.
    virtual PassDecision decide(const FrameContext& ctx) const = 0;
    // (Re)allocates targets for ctx's canvas / plan. Called before every frame the pass runs:
    // it must return at once unless a size changed (reallocating costs page faults on every
    // target, and would drop state such as the temporal history).
    virtual void resize(const FrameContext& ctx) = 0;
    virtual void execute(FrameContext& ctx, PassResources& res) = 0;

    // True for passes whose output depends only on the scene and the frame plan (lights, their
    // matrices, shadow layers, VPL allocation) and never on the camera: shadow maps + RSMs,
    // VPLs, imperfect shadow maps. Scenes are static, so while the plan is unchanged the graph
    // reuses their last output (republishing what they published) instead of re-running them.
    virtual bool cameraIndependent() const { return false; }

    // True when the pass's persistent output from its last run is still what this frame needs
    // (the pass knows its own input generation: the environment pass's "no new environment
    // frame"). The graph then republishes that output instead of running the pass, provided the
    // pass ran in the previous frame (a skipped pass always runs again).
    virtual bool upToDate(const FrameContext& /*ctx*/) const { return false; }
};

}  // namespace mirage::render
