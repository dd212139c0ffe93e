#pragma once
// The frame as a graph of passes (after google/filament's FrameGraph and Falcor's render graph):
//  - set-up: each pass declares in setup() the resources it writes (each attachment on its own,
//    with format and size rule) and reads (required or optional); what comes from outside the
//    frame is imported (camera image, environment map). compile() checks that every required
//    read has an earlier writer or an import (an optional one may have no writer in the graph),
//    that no resource has two writers, and that the outputs are written;
//  - per frame: each pass's decide() states the scene condition it needs ("no specular object in
//    view"); a pass whose required read is not written this frame is skipped with the reason of
//    the pass that does not write it; then passes are culled backwards from the outputs (a pass
//    no running pass reads is not run). Camera-independent passes reuse their last output while
//    the frame plan is unchanged. Every pass is timed with a GL timer query;
//  - textures reach a pass only by name, through the PassResources view of its own declarations:
//    looking up or publishing a resource the pass did not declare throws, so no pass holds or
//    reads another pass's objects.
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "core/gl/Objects.h"
#include "render/RenderPass.h"
#include "render/Resource.h"

namespace mirage::render {

struct PassReport {
    std::string name;
    bool ran = false;
    bool reused = false;  // not run: the output of an earlier frame was reused (still valid)
    std::string reason;
    // The pass's time (0 when skipped), ms: with RendererOptions::syncPasses the wall time from
    // a glFinish before it to one after it (its whole cost on a software rasteriser, compute
    // dispatches included); otherwise its GL_TIME_ELAPSED, overlapping the other passes' work.
    double gpuMs = 0.0;
};

struct FrameReport {
    std::vector<PassReport> passes;
    double totalGpuMs = 0.0;
    bool ran(const std::string& pass) const;
    bool reused(const std::string& pass) const;  // its output of an earlier frame was reused
    std::string summary() const;  // one line per pass: "name: ran|skipped (reason) x.xx ms"
};

class FrameGraph {
public:
    FrameGraph() = default;
    FrameGraph(const FrameGraph&) = delete;
    FrameGraph& operator=(const FrameGraph&) = delete;

    // Set-up, before compile(). Passes run in the order they are added.
    void importTexture(Resource r, GLenum format, SizeRule size, std::string what);
    RenderPass& addPass(std::unique_ptr<RenderPass> pass);
    void markOutput(Resource r);
    // Checks the declarations (throws mirage::Error naming the pass and the resource: a bug in
    // a pass's setup) and creates the timer queries.
    void compile();

    // The texture behind an import for the following frames (set before execute()).
    void setImport(Resource r, const gl::Texture& texture);

    // Runs one frame. `staticKey` identifies what camera-independent passes' output depends on
    // besides the scene (light matrices, plan): equal keys let them reuse their last output.
    const FrameReport& execute(FrameContext& ctx, const std::string& staticKey);

    // This frame's resources (after execute()), for readbacks.
    bool has(Resource r) const;
    const gl::Texture& texture(Resource r) const;  // throws mirage::Error if not written
    const gl::Buffer& buffer(Resource r) const;    // throws mirage::Error if not written

    // The pass list in frame order (report, CSV and bench columns come from it).
    std::vector<std::string> passNames() const;
    const FrameReport& lastReport() const { return report_; }
    // The graph as text: every pass with what it writes (format, size rule) and reads, and what
    // it did in the last frame and why.
    std::string describe() const;
    // The same as a markdown table (docs/realtime-renderer.md): one row per pass.
    std::string markdown() const;
    // The same as a Graphviz digraph: passes as boxes (grey: skipped), edges from writer to
    // reader labelled with the resources (dashed: optional reads).
    std::string dot() const;

    struct Node {
        std::unique_ptr<RenderPass> pass;
        std::vector<ResourceWrite> writes;
        std::vector<ResourceRead> reads;
    };
    const std::vector<Node>& nodes() const { return nodes_; }

private:
    friend class PassResources;
    struct Slot {
        const gl::Texture* texture = nullptr;
        const gl::Buffer* buffer = nullptr;
        explicit operator bool() const { return texture || buffer; }
    };
    struct Import {
        Resource id;
        GLenum format = 0;
        SizeRule size = SizeRule::Scene;
        std::string what;
        const gl::Texture* texture = nullptr;
    };
    const Import* findImport(Resource r) const;
    void plan(FrameContext& ctx, std::vector<int>& run);
    void checkPublished(const Node& n, Resource r, const Slot& s, const FrameContext& ctx) const;

    std::vector<Node> nodes_;
    std::vector<Import> imports_;
    std::vector<Resource> outputs_;
    std::array<int, kResourceCount> writer_{};  // pass index per resource, -1 none
    bool compiled_ = false;
    std::vector<gl::TimerQuery> timers_;
    std::vector<double> syncedMs_;  // per pass, this frame: wall ms between its two glFinish
    // This frame's resources, and what each pass published when it last ran (replayed when a
    // camera-independent pass reuses its output).
    std::array<Slot, kResourceCount> current_{};
    std::vector<std::vector<std::pair<Resource, Slot>>> published_;
    std::string staticKey_;
    std::vector<bool> staticOutputValid_;
    std::vector<bool> outputHeld_;  // published_[i] is the output of the pass's latest run and
                                    // the pass ran (or was reused) in every frame since
    FrameReport report_;
};

// What a pass sees of the frame's resources during execute(): only what its setup() declared.
class PassResources {
public:
    // A declared read. An undeclared one fails an MR_CHECK (std::logic_error naming the pass and
    // the resource: a bug in the pass), as does a read nothing published this frame (for a
    // required read that means its writer did not publish what it declared).
    const gl::Texture& texture(Resource r) const;
    const gl::Buffer& buffer(Resource r) const;
    // A declared read (typically optional) is available this frame.
    bool has(Resource r) const;
    // A declared optional read, or `fallback` when it is not available this frame.
    const gl::Texture& textureOr(Resource r, const gl::Texture& fallback) const;
    // A declared write: checked against the declared format and size rule (MR_CHECK).
    void publish(Resource r, const gl::Texture& texture);
    void publish(Resource r, const gl::Buffer& buffer);

private:
    friend class FrameGraph;
    PassResources(FrameGraph& g, size_t node, const FrameContext& ctx)
        : graph_(g), node_(node), ctx_(ctx) {}
    const ResourceRead& declaredRead(Resource r) const;
    void publishSlot(Resource r, const FrameGraph::Slot& s);
    FrameGraph& graph_;
    size_t node_;
    const FrameContext& ctx_;
};

}  // namespace mirage::render
