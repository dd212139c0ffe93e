#pragma once
// A render pass of the real-time renderer (render/FrameGraph.h): declares in setup() the named
// resources it writes and reads, states per frame the scene condition it needs (decide()),
// allocates its targets in resize(), and records GL work in execute() without allocating,
// getting other passes' textures only by name from its PassResources view. Shaders live beside
// the pass (render/passes/<pass>/) and are embedded at build time.
#include <initializer_list>
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

// A framebuffer over textures the graph allocates (Storage::Transient): made again only when the
// graph hands the pass other textures than the last time (it keeps an assignment while the
// frame's passes and sizes stay the same).
class TargetFramebuffer {
public:
    explicit TargetFramebuffer(std::string label) : label_(std::move(label)) {}
    // Binds the framebuffer with `colors` as colour attachments 0, 1, ...
    void bind(std::initializer_list<const gl::Texture*> colors);

private:
    std::string label_;
    std::vector<GLuint> ids_;
    gl::Framebuffer fbo_;
};

struct PassDecision {
    bool run = true;
    std::string reason;  // e.g. "2 lights have casters in their cone" / "no virtual object lit"
};

// One declared write / read of a pass.
struct ResourceWrite {
    Resource id;
    bool buffer = false;
    TextureDesc desc;       // textures: format, size rule, storage (buffers: format 0)
    bool modifies = false;  // a new version of a resource an earlier pass created
    int version = 0;        // set by the graph: 0 for a create, the previous version + 1
    bool persistent() const { return desc.storage == Storage::Persistent; }
};
struct ResourceRead {
    Resource id;
    bool optional = false;
    int version = -1;  // the version read: the newest at this pass (set by the graph), or the
                       // version of the handle the pass named (checked to be the newest)
};

class FrameGraph;

// Collects a pass's declarations (FrameGraph::addPass calls RenderPass::setup with it) and
// returns handles to the versions they name (after google/filament's FrameGraph::Builder).
class PassBuilder {
public:
    // A builder that only records (its handles name no version): to inspect a pass's setup.
    PassBuilder() = default;

    // A texture the pass creates (version 0), with its descriptor: the graph allocates a
    // Storage::Transient one (PassResources::target), the pass allocates and publishes the rest.
    TextureHandle create(Resource r, TextureDesc desc);
    // A buffer the pass creates and publishes. persistent: kept across frames by the pass.
    void createBuffer(Resource r, SizeRule size, bool persistent = false);
    // A new version of a texture an earlier pass created: the pass reads the newest version
    // (required, or optional: when no earlier version exists this frame the pass makes the
    // resource from scratch) and writes the next one, with its own descriptor (a filter cannot
    // write in place, so a version may live in another texture). Readers declared after this
    // pass read the new version; when this pass is skipped, they read the previous one.
    TextureHandle modify(Resource r, TextureDesc desc);
    TextureHandle modifyOptional(Resource r, TextureDesc desc);
    // A resource the pass reads, at its newest version: required (the pass is skipped when no
    // pass writes it this frame) or optional (the pass checks PassResources::has and falls back).
    TextureHandle read(Resource r);
    TextureHandle readOptional(Resource r);
    // A read of the version `h` names: the graph refuses it (mirage::Error at addPass) unless it
    // is still the newest version, i.e. no pass modified the resource since `h` was returned.
    TextureHandle read(TextureHandle h);

    // An import or an earlier pass (or this one) declares the resource: a pass whose reads are
    // chosen at run time (an option naming a resource) checks them with this. Always true for
    // a recording builder (nothing to check against).
    bool declared(Resource r) const { return !graph_ || newestVersion(r) >= 0; }

    const std::vector<ResourceWrite>& writes() const { return writes_; }
    const std::vector<ResourceRead>& reads() const { return reads_; }

private:
    friend class FrameGraph;
    explicit PassBuilder(const FrameGraph* g) : graph_(g) {}
    int newestVersion(Resource r) const;
    const FrameGraph* graph_ = nullptr;
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
    // A camera-independent pass whose output changes from frame to frame by choice (the VPLs'
    // per-frame rotation) returns false here for that frame: the graph then runs it although the
    // plan is unchanged, and with it every camera-independent pass that reads its output.
    virtual bool staticThisFrame(const FrameContext& /*ctx*/) const { return true; }

    // True when the pass's persistent output from its last run is still what this frame needs
    // (the pass knows its own input generation: the environment pass's "no new environment
    // frame"). The graph then republishes that output instead of running the pass, provided the
    // pass ran in the previous frame (a skipped pass always runs again).
    virtual bool upToDate(const FrameContext& /*ctx*/) const { return false; }
};

}  // namespace mirage::render
