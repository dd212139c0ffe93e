#pragma once
// The frame as a graph of passes (after google/filament's FrameGraph and Falcor's render graph):
//  - set-up: each pass declares in setup() the resources it creates (each attachment on its own,
//    with a descriptor: format, size rule, storage), the ones it modifies (a new version of a
//    resource an earlier pass created) and the ones it reads (required or optional); what comes
//    from outside the frame is imported (camera image, environment map). There is no central
//    list of resources: a resource's name is declared by the pass that creates it. compile()
//    checks that every required read has an earlier writer or an import (an optional one may have
//    no writer in the graph), that a resource is created once, and that the outputs are written;
//  - per frame: each pass's decide() states the scene condition it needs ("no specular object in
//    view"); a pass whose required read is not written this frame is skipped with the reason of
//    the pass that does not write it; a skipped modifier passes the previous version through;
//    then passes are culled backwards from the outputs (a pass no running pass reads is not run).
//    Camera-independent passes reuse their last output while the frame plan is unchanged. Every
//    pass is timed;
//  - the graph allocates the transient textures (Storage::Transient) of the passes that run from
//    their descriptors, and gives two of them the same texture when their lifetimes (writer to
//    last reader) do not overlap; pass-owned and persistent ones and imports are the passes' or
//    the renderer's;
//  - textures reach a pass only by name, through the PassResources view of its own declarations:
//    looking up or publishing a resource the pass did not declare throws, so no pass holds or
//    reads another pass's objects.
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
    // The pass's time (0 when skipped), ms: with RendererOptions::graph.syncPasses the wall time
    // from a glFinish before it to one after it (its whole cost on a software rasteriser, compute
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
    // Imports precede the passes that read them.
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

    // This frame's resources (after execute()) at their newest version written, for readbacks.
    // A transient texture whose memory a later resource reused in the frame is gone: texture()
    // throws mirage::Error naming it (as when the frame did not write it).
    bool has(Resource r) const;
    // ... and is a texture (not a buffer): for a pass whose reads an option names.
    bool hasTexture(Resource r) const;
    const gl::Texture& texture(Resource r) const;
    const gl::Buffer& buffer(Resource r) const;

    // The newest version of `r` declared so far (-1: none), for PassBuilder.
    int newestVersion(Resource r) const;

    // The transient textures of the last frame: the bytes their descriptors ask for, and the bytes
    // of the distinct textures the graph gave them (less where lifetimes did not overlap).
    struct TransientMemory {
        size_t requestedBytes = 0;
        size_t allocatedBytes = 0;
        int resources = 0, textures = 0;
    };
    const TransientMemory& transientMemory() const { return memory_; }
    // The texture behind a transient resource this frame (0 if none): tests of the aliasing.
    GLuint transientTextureId(Resource r) const;

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
        std::vector<int> writeValues, readValues;  // value ids (see Value); -1 unresolved
    };
    const std::vector<Node>& nodes() const { return nodes_; }

private:
    friend class PassResources;
    struct Slot {
        const gl::Texture* texture = nullptr;
        const gl::Buffer* buffer = nullptr;
        explicit operator bool() const { return texture || buffer; }
    };
    // One version of one resource: written by one pass (or imported: writer -1).
    struct Value {
        int resource = -1, version = 0;
        int writer = -1;    // node index; -1: an import
        int previous = -1;  // the value of the version before (-1 for version 0)
        bool buffer = false;
        TextureDesc desc;
        std::string what;                       // imports: what it is
        const gl::Texture* imported = nullptr;  // imports: this frame's texture
    };
    // A texture the graph allocated for transient resources.
    struct PooledTexture {
        gl::Texture texture;
        GLenum format = 0;
        int width = 0, height = 0, layers = 1;
        int busyUntil = -1;  // this frame: node index of its current resource's last reader
        bool usedThisFrame = false;
    };
    int findResource(Resource r) const;
    int addResource(Resource r);
    int addValue(int resource, int writer, bool buffer, const TextureDesc& desc);
    int creatorOf(int value) const;  // the writer of the value's version 0
    int resolve(int value, const std::vector<bool>& available) const;
    void resolveDeclarations(Node& n, int index);
    void plan(FrameContext& ctx, std::vector<int>& run);
    void allocateTransients(const FrameContext& ctx, const std::vector<int>& run);
    void checkPublished(const Node& n, int write, const Slot& s, const FrameContext& ctx) const;
    std::string valueName(int value) const;

    std::vector<Node> nodes_;
    std::vector<Resource> resources_;
    std::vector<std::vector<int>> versions_;  // per resource: value id of each version
    std::vector<Value> values_;
    std::vector<Resource> outputNames_;
    std::vector<int> outputs_;  // resources
    bool compiled_ = false;
    std::vector<gl::TimerQuery> timers_;
    std::vector<double> syncedMs_;  // per pass, this frame: wall ms between its two glFinish
    // This frame: the resources by value, what each pass's reads resolved to (a skipped
    // modifier's readers get the version before), and what each pass published when it last ran
    // (replayed when a camera-independent pass reuses its output).
    std::vector<Slot> current_;
    std::vector<std::vector<int>> resolvedReads_;
    std::vector<std::vector<std::pair<int, Slot>>> published_;
    std::string staticKey_;
    std::vector<bool> staticOutputValid_;
    std::vector<bool> outputHeld_;  // published_[i] is the output of the pass's latest run and
                                    // the pass ran (or was reused) in every frame since
    // Transient textures: the pool, each value's texture this frame (-1 none), and whether a
    // later value reused it within the frame (then it is gone after the frame).
    std::vector<PooledTexture> pool_;
    std::vector<int> poolOf_;
    std::vector<bool> overwritten_;
    TransientMemory memory_;
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
    // ... and is a texture (not a buffer): for a pass whose reads an option names.
    bool hasTexture(Resource r) const;
    // A declared optional read, or `fallback` when it is not available this frame.
    const gl::Texture& textureOr(Resource r, const gl::Texture& fallback) const;
    // A declared write: checked against the declared format and size rule (MR_CHECK).
    void publish(Resource r, const gl::Texture& texture);
    void publish(Resource r, const gl::Buffer& buffer);
    // The texture the graph allocated for a declared Storage::Transient write (published by the
    // graph; its contents are undefined until the pass writes them).
    const gl::Texture& target(Resource r) const;

private:
    friend class FrameGraph;
    PassResources(FrameGraph& g, size_t node, const FrameContext& ctx)
        : graph_(g), node_(node), ctx_(ctx) {}
    int declaredRead(Resource r) const;  // index into the node's reads
    int declaredWrite(Resource r) const;
    void publishSlot(Resource r, const FrameGraph::Slot& s);
    FrameGraph& graph_;
    size_t node_;
    const FrameContext& ctx_;
};

}  // namespace mirage::render
