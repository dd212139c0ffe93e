#include "render/FrameGraph.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include <fmt/format.h>

#include "core/Error.h"

namespace mirage::render {
namespace {

// Expected width, height and layers of a texture of size rule `s` this frame; false where the
// rule depends on data the graph does not see (impostor layers, scene imports).
bool expectedSize(SizeRule s, const FrameContext& c, int& w, int& h, int& layers) {
    const RendererOptions& o = c.options;
    layers = 1;
    switch (s) {
        case SizeRule::Canvas:
            w = c.canvasWidth(), h = c.canvasHeight();
            return true;
        case SizeRule::Camera:
            w = c.projection.camera.width, h = c.projection.camera.height;
            return true;
        case SizeRule::Gather:
        case SizeRule::GatherTiles: {
            const int sc = c.gatherScale(), k = std::max(1, o.indirect.interleave);
            w = (c.canvasWidth() + sc - 1) / sc, h = (c.canvasHeight() + sc - 1) / sc;
            if (s == SizeRule::GatherTiles) w = (w + k - 1) / k * k, h = (h + k - 1) / k * k;
            return true;
        }
        case SizeRule::ShadowAtlas:
        case SizeRule::RsmAtlas:
            w = h = s == SizeRule::ShadowAtlas ? o.shadow.mapSize : o.shadow.rsmSize;
            layers = std::max(1, c.plan.shadowLayers);
            return true;
        case SizeRule::FocusedShadowAtlas:
            w = h = o.shadow.mapSize;
            layers = std::max(1, c.plan.shadowLayers) + c.plan.focusLayers;
            return true;
        case SizeRule::IsmAtlas:
            w = h = ismTilesPerRow(o.vpl.count) * o.ism.tileSize;
            return true;
        case SizeRule::CausticMap:
            w = h = o.caustic.mapSize;
            layers = std::max(1, c.plan.causticLayers);
            return true;
        case SizeRule::Impostor:
        case SizeRule::Vpl:
        case SizeRule::Scene:
            return false;
    }
    return false;
}

size_t textureBytes(GLenum format, int w, int h, int layers) {
    return bytesPerTexel(format) * size_t(w) * size_t(h) * size_t(layers);
}

}  // namespace

bool FrameReport::ran(const std::string& pass) const {
    for (const PassReport& p : passes)
        if (p.name == pass) return p.ran;
    return false;
}

bool FrameReport::reused(const std::string& pass) const {
    for (const PassReport& p : passes)
        if (p.name == pass) return p.reused;
    return false;
}

std::string FrameReport::summary() const {
    std::ostringstream s;
    for (const PassReport& p : passes)
        s << fmt::format("{:<10} {:<7} {:7.2f} ms  {}\n", p.name,
                         p.ran ? "ran" : (p.reused ? "reused" : "skipped"), p.gpuMs, p.reason);
    s << fmt::format("{:<10} {:<7} {:7.2f} ms\n", "total", "", totalGpuMs);
    return s.str();
}

int FrameGraph::findResource(Resource r) const {
    for (size_t i = 0; i < resources_.size(); ++i)
        if (resources_[i] == r) return int(i);
    return -1;
}

int FrameGraph::addResource(Resource r) {
    resources_.push_back(r);
    versions_.emplace_back();
    return int(resources_.size()) - 1;
}

int FrameGraph::addValue(int resource, int writer, bool buffer, const TextureDesc& desc) {
    Value v;
    v.resource = resource;
    v.version = int(versions_[size_t(resource)].size());
    v.writer = writer;
    v.previous = versions_[size_t(resource)].empty() ? -1 : versions_[size_t(resource)].back();
    v.buffer = buffer;
    v.desc = desc;
    values_.push_back(v);
    versions_[size_t(resource)].push_back(int(values_.size()) - 1);
    return int(values_.size()) - 1;
}

int FrameGraph::creatorOf(int value) const {
    while (values_[size_t(value)].previous >= 0) value = values_[size_t(value)].previous;
    return values_[size_t(value)].writer;
}

int FrameGraph::newestVersion(Resource r) const {
    const int i = findResource(r);
    return i < 0 ? -1 : int(versions_[size_t(i)].size()) - 1;
}

std::string FrameGraph::valueName(int value) const {
    const Value& v = values_[size_t(value)];
    const char* name = resources_[size_t(v.resource)].name;
    return v.version == 0 ? std::string(name) : fmt::format("{} v{}", name, v.version);
}

void FrameGraph::importTexture(Resource r, GLenum format, SizeRule size, std::string what) {
    MR_CHECK(!compiled_, "FrameGraph::importTexture after compile()");
    MR_CHECK(findResource(r) < 0, std::string("resource ") + r.name + " imported twice");
    const int v = addValue(addResource(r), -1, false, {format, size, Storage::PassOwned});
    values_[size_t(v)].what = std::move(what);
}

// The versions a new pass's declarations name: reads resolve to the newest version so far (a
// handle's version must be it), creates make version 0 and modifies the next.
void FrameGraph::resolveDeclarations(Node& n, int index) {
    const char* pass = n.pass->name();
    for (ResourceRead& r : n.reads) {
        const int res = findResource(r.id);
        const int newest = res < 0 ? -1 : int(versions_[size_t(res)].size()) - 1;
        if (r.version >= 0 && r.version != newest) {
            const int w = values_[size_t(versions_[size_t(res)][size_t(newest)])].writer;
            throw Error(fmt::format(
                "frame graph: {} reads {} version {}, but {} wrote version {} before it (a "
                "modified resource's older versions are gone): read the newest handle",
                pass, r.id.name, r.version, w >= 0 ? nodes_[size_t(w)].pass->name() : "an import",
                newest));
        }
        r.version = newest;
        n.readValues.push_back(newest < 0 ? -1 : versions_[size_t(res)][size_t(newest)]);
    }
    for (ResourceWrite& w : n.writes) {
        int res = findResource(w.id);
        if (!w.modifies && res >= 0) {
            const int first = values_[size_t(versions_[size_t(res)][0])].writer;
            throw Error(
                first < 0
                    ? fmt::format("frame graph: {} writes {}, which is imported", pass, w.id.name)
                    : fmt::format("frame graph: {} is created by both {} and {}; "
                                  "a later pass modifies it (PassBuilder::modify)",
                                  w.id.name, nodes_[size_t(first)].pass->name(), pass));
        }
        if (w.modifies && res < 0)
            throw Error(fmt::format("frame graph: {} modifies {}, which no earlier pass creates",
                                    pass, w.id.name));
        if (res < 0) res = addResource(w.id);
        if (w.modifies && values_[size_t(versions_[size_t(res)][0])].writer < 0)
            throw Error(
                fmt::format("frame graph: {} writes {}, which is imported", pass, w.id.name));
        const int v = addValue(res, index, w.buffer, w.desc);
        w.version = values_[size_t(v)].version;
        n.writeValues.push_back(v);
    }
}

RenderPass& FrameGraph::addPass(std::unique_ptr<RenderPass> pass) {
    MR_CHECK(!compiled_, "FrameGraph::addPass after compile()");
    MR_CHECK(pass != nullptr, "FrameGraph::addPass(nullptr)");
    PassBuilder b(this);
    pass->setup(b);
    Node n;
    n.pass = std::move(pass);
    n.writes = std::move(b.writes_);
    n.reads = std::move(b.reads_);
    for (const ResourceWrite& w : n.writes)
        MR_CHECK(w.desc.storage != Storage::Transient ||
                     (!w.buffer && !n.pass->cameraIndependent() && w.desc.size != SizeRule::Scene &&
                      w.desc.size != SizeRule::Impostor && w.desc.size != SizeRule::Vpl),
                 fmt::format("pass {}: transient {} must be a texture of a frame-sized rule, "
                             "written by a pass that runs whenever it is read",
                             n.pass->name(), w.id.name));
    resolveDeclarations(n, int(nodes_.size()));
    nodes_.push_back(std::move(n));
    return *nodes_.back().pass;
}

void FrameGraph::markOutput(Resource r) {
    outputNames_.push_back(r);
}

void FrameGraph::compile() {
    MR_CHECK(!compiled_, "FrameGraph::compile called twice");
    for (size_t i = 0; i < nodes_.size(); ++i) {
        const Node& n = nodes_[i];
        for (size_t k = 0; k < n.reads.size(); ++k) {
            const ResourceRead& r = n.reads[k];
            // An optional read may have no writer in this graph (then it is never available).
            if (n.readValues[k] >= 0 || r.optional) continue;
            const int res = findResource(r.id);
            throw Error(fmt::format(
                "frame graph: {} reads {}, which {}", n.pass->name(), r.id.name,
                res < 0 ? "no pass writes and nothing imports"
                        : fmt::format(
                              "only {} writes, after it (passes run in the order added)",
                              nodes_[size_t(creatorOf(versions_[size_t(res)][0]))].pass->name())));
        }
    }
    for (Resource o : outputNames_) {
        const int res = findResource(o);
        if (res < 0 || values_[size_t(versions_[size_t(res)].back())].writer < 0)
            throw Error(fmt::format("frame graph: output {} has no writer", o.name));
        outputs_.push_back(res);
    }
    for (const Node& n : nodes_) timers_.emplace_back(std::string("timer ") + n.pass->name());
    // Prime every query once: on llvmpipe the very first GL_TIME_ELAPSED result of a process can
    // be garbage (seen: 3.4e6 ms), which would spoil the first frame's report.
    {
        gl::Texture scratch = gl::Texture::create2D("timer priming", 8, 8, GL_RGBA8);
        gl::Framebuffer fb("timer priming fbo");
        fb.attachColor(0, scratch);
        fb.finalize(1);
        fb.bind();
        for (gl::TimerQuery& t : timers_) {
            t.begin();
            glClear(GL_COLOR_BUFFER_BIT);
            t.end();
            (void)t.elapsedMs();
        }
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
    }
    published_.assign(nodes_.size(), {});
    resolvedReads_.assign(nodes_.size(), {});
    poolOf_.assign(values_.size(), -1);
    overwritten_.assign(values_.size(), false);
    outputHeld_.assign(nodes_.size(), false);
    report_.passes.assign(nodes_.size(), PassReport{});
    for (size_t i = 0; i < nodes_.size(); ++i) {
        report_.passes[i].name = nodes_[i].pass->name();
        report_.passes[i].reason = "not run yet";
    }
    compiled_ = true;
}

void FrameGraph::setImport(Resource r, const gl::Texture& texture) {
    const int res = findResource(r);
    MR_CHECK(res >= 0 && values_[size_t(versions_[size_t(res)][0])].writer < 0,
             std::string("setImport: ") + r.name + " was not declared an import");
    Value& v = values_[size_t(versions_[size_t(res)][0])];
    MR_CHECK(texture.format() == v.desc.format,
             fmt::format("import {} is {}, declared {}", r.name, formatName(texture.format()),
                         formatName(v.desc.format)));
    v.imported = &texture;
}

// The value a read of `value` gets this frame: the newest version up to it that is available (a
// skipped modifier passes the version before through); -1 when none is.
int FrameGraph::resolve(int value, const std::vector<bool>& available) const {
    while (value >= 0 && !available[size_t(value)]) value = values_[size_t(value)].previous;
    return value;
}

// Which passes run this frame, and why each does or does not (into report_).
void FrameGraph::plan(FrameContext& ctx, std::vector<int>& run) {
    const size_t n = nodes_.size();
    run.assign(n, 0);
    std::vector<bool> available(values_.size(), false);
    for (size_t v = 0; v < values_.size(); ++v)
        if (values_[v].writer < 0) available[v] = values_[v].imported != nullptr;
    // Forward: the scene conditions, then the required reads.
    std::vector<std::string> rootCause(n);
    for (size_t i = 0; i < n; ++i) {
        const Node& node = nodes_[i];
        PassReport& rep = report_.passes[i];
        rep = PassReport{};
        rep.name = node.pass->name();
        std::vector<int>& resolved = resolvedReads_[i];
        resolved.assign(node.reads.size(), -1);
        const PassDecision d = node.pass->decide(ctx);
        rep.reason = rootCause[i] = d.reason;
        if (!d.run) continue;
        int missing = -1;
        for (size_t k = 0; k < node.reads.size(); ++k) {
            resolved[k] = node.readValues[k] < 0 ? -1 : resolve(node.readValues[k], available);
            if (missing < 0 && !node.reads[k].optional && resolved[k] < 0) missing = int(k);
        }
        if (missing >= 0) {
            const ResourceRead& r = node.reads[size_t(missing)];
            const int w = creatorOf(node.readValues[size_t(missing)]);
            rep.reason = w < 0
                             ? fmt::format("needs {}, which is not imported this frame", r.id.name)
                             : fmt::format("needs {} ({}: {})", r.id.name,
                                           nodes_[size_t(w)].pass->name(), rootCause[size_t(w)]);
            rootCause[i] = w < 0 ? rep.reason : rootCause[size_t(w)];
            continue;
        }
        run[i] = 1;
        for (int v : node.writeValues) available[size_t(v)] = true;
    }
    // Backward from the outputs: a pass runs only if a running pass (or the output) reads it.
    std::vector<bool> needed(values_.size(), false);
    for (int o : outputs_) {
        const int v = resolve(versions_[size_t(o)].back(), available);
        if (v >= 0) needed[size_t(v)] = true;
    }
    for (size_t k = n; k-- > 0;) {
        if (!run[k]) continue;
        const Node& node = nodes_[k];
        std::string writes;
        bool read = false;
        for (int v : node.writeValues) {
            writes += (writes.empty() ? "" : ", ") + valueName(v);
            read = read || needed[size_t(v)];
        }
        if (!read) {
            run[k] = 0;
            report_.passes[k].reason = "culled: no pass this frame reads " + writes;
            continue;
        }
        for (int v : resolvedReads_[k])
            if (v >= 0) needed[size_t(v)] = true;
    }
}

// Gives every transient texture written this frame a pooled texture of its descriptor whose
// previous resource's last reader ran before its writer; allocates one where none is free.
void FrameGraph::allocateTransients(const FrameContext& ctx, const std::vector<int>& run) {
    const size_t n = nodes_.size();
    std::vector<int> lastUse(values_.size(), -1);
    for (size_t i = 0; i < n; ++i) {
        if (!run[i]) continue;
        for (int v : nodes_[i].writeValues)
            lastUse[size_t(v)] = std::max(lastUse[size_t(v)], int(i));
        for (int v : resolvedReads_[i])
            if (v >= 0) lastUse[size_t(v)] = std::max(lastUse[size_t(v)], int(i));
    }
    for (int o : outputs_)  // outputs are read after the frame
        for (int v : versions_[size_t(o)]) lastUse[size_t(v)] = int(n);
    for (PooledTexture& p : pool_) p.busyUntil = -1, p.usedThisFrame = false;
    std::vector<int> previousPool = poolOf_;
    std::vector<int> lastValueOf(pool_.size(), -1);
    poolOf_.assign(values_.size(), -1);
    overwritten_.assign(values_.size(), false);
    memory_ = TransientMemory{};
    for (size_t i = 0; i < n; ++i) {
        if (!run[i]) continue;
        const Node& node = nodes_[i];
        for (size_t k = 0; k < node.writes.size(); ++k) {
            const ResourceWrite& w = node.writes[k];
            if (w.desc.storage != Storage::Transient) continue;
            const int v = node.writeValues[k];
            int width = 0, height = 0, layers = 1;
            MR_CHECK(expectedSize(w.desc.size, ctx, width, height, layers),
                     std::string("transient size rule of ") + w.id.name);
            const auto fits = [&](int p) {
                const PooledTexture& t = pool_[size_t(p)];
                return p >= 0 && p < int(pool_.size()) && t.busyUntil < int(i) &&
                       t.format == w.desc.format && t.width == width && t.height == height &&
                       t.layers == layers;
            };
            // The texture it had last frame first: a stable assignment keeps passes' cached
            // framebuffers valid.
            int chosen = fits(previousPool[size_t(v)]) ? previousPool[size_t(v)] : -1;
            for (int p = 0; chosen < 0 && p < int(pool_.size()); ++p)
                if (fits(p)) chosen = p;
            if (chosen < 0) {
                PooledTexture t;
                const std::string label = std::string("transient ") + w.id.name;
                t.texture = layers > 1 ? gl::Texture::create2DArray(label, width, height, layers,
                                                                    w.desc.format)
                                       : gl::Texture::create2D(label, width, height, w.desc.format);
                t.format = w.desc.format, t.width = width, t.height = height, t.layers = layers;
                pool_.push_back(std::move(t));
                lastValueOf.push_back(-1);
                chosen = int(pool_.size()) - 1;
            }
            PooledTexture& t = pool_[size_t(chosen)];
            if (lastValueOf[size_t(chosen)] >= 0)
                overwritten_[size_t(lastValueOf[size_t(chosen)])] = true;
            lastValueOf[size_t(chosen)] = v;
            t.busyUntil = lastUse[size_t(v)];
            poolOf_[size_t(v)] = chosen;
            const size_t bytes = textureBytes(w.desc.format, width, height, layers);
            memory_.requestedBytes += bytes;
            ++memory_.resources;
            if (!t.usedThisFrame) memory_.allocatedBytes += bytes, ++memory_.textures;
            t.usedThisFrame = true;
        }
    }
}

const FrameReport& FrameGraph::execute(FrameContext& ctx, const std::string& staticKey) {
    MR_CHECK(compiled_, "FrameGraph::execute before compile()");
    current_.assign(values_.size(), Slot{});
    for (size_t v = 0; v < values_.size(); ++v)
        if (values_[v].writer < 0) current_[v].texture = values_[v].imported;
    if (staticKey != staticKey_ || staticOutputValid_.size() != nodes_.size()) {
        staticKey_ = staticKey;
        staticOutputValid_.assign(nodes_.size(), false);
    }
    std::vector<int> run;
    plan(ctx, run);
    allocateTransients(ctx, run);
    report_.totalGpuMs = 0.0;
    const RendererOptions& o = ctx.options;
    using Clock = std::chrono::steady_clock;
    const auto msSince = [](Clock::time_point t) {
        return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
    };
    const Clock::time_point frameStart = Clock::now();
    syncedMs_.assign(nodes_.size(), 0.0);
    // Values a camera-independent pass wrote anew this frame (it ran instead of being reused): a
    // camera-independent pass that reads one of them cannot reuse its output either.
    std::vector<char> rewritten(values_.size(), 0);
    for (size_t i = 0; i < nodes_.size(); ++i) {
        Node& node = nodes_[i];
        RenderPass& p = *node.pass;
        PassReport& rep = report_.passes[i];
        if (!run[i]) {
            staticOutputValid_[i] = false;
            outputHeld_[i] = false;
            continue;
        }
        if (outputHeld_[i] && p.upToDate(ctx)) {
            for (const auto& [value, slot] : published_[i]) current_[size_t(value)] = slot;
            rep.reused = true;
            rep.reason = "reused: " + rep.reason;
            continue;
        }
        const bool inputRewritten =
            std::any_of(node.readValues.begin(), node.readValues.end(),
                        [&](int v) { return v >= 0 && rewritten[size_t(v)]; });
        if (p.cameraIndependent() && o.graph.reuseStaticPasses && staticOutputValid_[i] &&
            p.staticThisFrame(ctx) && !inputRewritten) {
            for (const auto& [value, slot] : published_[i]) current_[size_t(value)] = slot;
            rep.reused = true;
            rep.reason = "reused: scene, lights and plan unchanged (" + rep.reason + ")";
            continue;
        }
        p.resize(ctx);  // no-op unless the plan's sizes changed (shadow layers, VPL count)
        published_[i].clear();
        PassResources view(*this, i, ctx);
        for (size_t k = 0; k < node.writes.size(); ++k)  // the graph's textures are published
            if (poolOf_[size_t(node.writeValues[k])] >= 0)
                view.publish(node.writes[k].id,
                             pool_[size_t(poolOf_[size_t(node.writeValues[k])])].texture);
        if (o.graph.syncPasses) {
            // The pass alone between two glFinish: its time is the wall time between them. On
            // llvmpipe that is what the pass costs, and GL_TIME_ELAPSED is not: it reads ~0 for
            // compute dispatches and has returned a timestamp (7e7 "ms") after them.
            glFinish();
            const Clock::time_point start = Clock::now();
            p.execute(ctx, view);
            glFinish();
            syncedMs_[i] = msSince(start);
        } else {
            timers_[i].begin();
            p.execute(ctx, view);
            timers_[i].end();
        }
        rep.ran = true;
        if (p.cameraIndependent())
            for (int v : node.writeValues)
                if (v >= 0) rewritten[size_t(v)] = 1;
        staticOutputValid_[i] = p.cameraIndependent();
        outputHeld_[i] = true;
    }
    for (size_t i = 0; i < nodes_.size(); ++i) {
        if (!report_.passes[i].ran) continue;
        double ms = syncedMs_[i];
        if (!o.graph.syncPasses) {
            // GPU time of the pass's commands, overlapping its neighbours'. No pass can take
            // longer than the frame so far (the result is in): a value beyond that is a broken
            // query result, reported as 0 rather than as a figure.
            ms = timers_[i].elapsedMs();
            if (!(ms >= 0.0 && ms <= msSince(frameStart) + 1.0)) ms = 0.0;
        }
        report_.passes[i].gpuMs = ms;
        report_.totalGpuMs += ms;
    }
    return report_;
}

bool FrameGraph::has(Resource r) const {
    const int res = findResource(r);
    if (res < 0) return false;
    for (auto it = versions_[size_t(res)].rbegin(); it != versions_[size_t(res)].rend(); ++it)
        if (current_.size() > size_t(*it) && current_[size_t(*it)])
            return !overwritten_[size_t(*it)];
    return false;
}

namespace {
[[noreturn]] void notProduced(Resource r, bool overwritten) {
    throw Error(overwritten ? std::string("buffer ") + r.name +
                                  " was transient and a later resource of the frame reused its "
                                  "texture; declare it Storage::PassOwned to read it back"
                            : std::string("buffer ") + r.name + " was not produced this frame");
}
}  // namespace

const gl::Texture& FrameGraph::texture(Resource r) const {
    const int res = findResource(r);
    if (res >= 0)
        for (auto it = versions_[size_t(res)].rbegin(); it != versions_[size_t(res)].rend(); ++it)
            if (current_.size() > size_t(*it) && current_[size_t(*it)].texture) {
                if (overwritten_[size_t(*it)]) notProduced(r, true);
                return *current_[size_t(*it)].texture;
            }
    notProduced(r, false);
}

const gl::Buffer& FrameGraph::buffer(Resource r) const {
    const int res = findResource(r);
    if (res >= 0)
        for (auto it = versions_[size_t(res)].rbegin(); it != versions_[size_t(res)].rend(); ++it)
            if (current_.size() > size_t(*it) && current_[size_t(*it)].buffer)
                return *current_[size_t(*it)].buffer;
    notProduced(r, false);
}

GLuint FrameGraph::transientTextureId(Resource r) const {
    const int res = findResource(r);
    if (res < 0) return 0;
    for (auto it = versions_[size_t(res)].rbegin(); it != versions_[size_t(res)].rend(); ++it)
        if (poolOf_.size() > size_t(*it) && poolOf_[size_t(*it)] >= 0)
            return pool_[size_t(poolOf_[size_t(*it)])].texture.id();
    return 0;
}

std::vector<std::string> FrameGraph::passNames() const {
    std::vector<std::string> names;
    for (const Node& n : nodes_) names.push_back(n.pass->name());
    return names;
}

void FrameGraph::checkPublished(const Node& n, int write, const Slot& s,
                                const FrameContext& ctx) const {
    const ResourceWrite* w = &n.writes[size_t(write)];
    const char* r = w->id.name;
    MR_CHECK(w->buffer == (s.buffer != nullptr),
             fmt::format("pass {} publishes {} as a {}, declared a {}", n.pass->name(), r,
                         s.buffer ? "buffer" : "texture", w->buffer ? "buffer" : "texture"));
    if (!s.texture) return;
    // An alias of one of the pass's reads (ShadowMapsReal = ShadowMaps) has that one's format.
    MR_CHECK(s.texture->format() == w->desc.format,
             fmt::format("pass {} publishes {} as {}, declared {}", n.pass->name(), r,
                         formatName(s.texture->format()), formatName(w->desc.format)));
    int ew = 0, eh = 0, el = 1;
    if (expectedSize(w->desc.size, ctx, ew, eh, el))
        MR_CHECK(s.texture->width() == ew && s.texture->height() == eh && s.texture->layers() == el,
                 fmt::format("pass {} publishes {} at {}x{}x{}, but its size rule ({}) gives "
                             "{}x{}x{}",
                             n.pass->name(), r, s.texture->width(), s.texture->height(),
                             s.texture->layers(), sizeRuleName(w->desc.size), ew, eh, el));
}

namespace {
const char* storageName(Storage s) {
    return s == Storage::Transient ? ", transient" : s == Storage::Persistent ? ", persistent" : "";
}
}  // namespace

std::string FrameGraph::describe() const {
    std::ostringstream s;
    s << "imports:";
    for (const Value& v : values_)
        if (v.writer < 0)
            s << fmt::format(" {} ({}, {})", resources_[size_t(v.resource)].name,
                             formatName(v.desc.format), v.what);
    s << "\noutputs:";
    for (int o : outputs_) s << " " << resources_[size_t(o)].name;
    const double MiB = 1.0 / (1024.0 * 1024.0);
    s << fmt::format(
        "\ntransient textures: {} in {} texture(s), {:.2f} MiB asked, {:.2f} MiB "
        "allocated\n",
        memory_.resources, memory_.textures, double(memory_.requestedBytes) * MiB,
        double(memory_.allocatedBytes) * MiB);
    for (size_t i = 0; i < nodes_.size(); ++i) {
        const Node& n = nodes_[i];
        const PassReport& r = report_.passes[i];
        s << fmt::format("\n{:>2} {:<10} {:<7} {}\n", i + 1, n.pass->name(),
                         r.ran ? "ran" : (r.reused ? "reused" : "skipped"), r.reason);
        for (size_t k = 0; k < n.writes.size(); ++k) {
            const ResourceWrite& w = n.writes[k];
            s << fmt::format("     {} {:<24} {:<12} {}{}\n", w.modifies ? "modifies" : "writes",
                             valueName(n.writeValues[k]), formatName(w.desc.format),
                             sizeRuleName(w.desc.size), storageName(w.desc.storage));
        }
        for (size_t k = 0; k < n.reads.size(); ++k) {
            const ResourceRead& rd = n.reads[k];
            const int v = n.readValues[k];
            const int w = v < 0 ? -1 : values_[size_t(v)].writer;
            s << fmt::format("     reads  {:<24} {:<12} from {}\n",
                             v < 0 ? std::string(rd.id.name) : valueName(v),
                             rd.optional ? "(optional)" : "",
                             v < 0    ? "nothing in this graph"
                             : w >= 0 ? nodes_[size_t(w)].pass->name()
                                      : "import");
        }
    }
    return s.str();
}

std::string FrameGraph::markdown() const {
    std::ostringstream s;
    s << "| # | pass | writes | reads (optional in italics) | this frame |\n"
         "|---|---|---|---|---|\n";
    for (size_t i = 0; i < nodes_.size(); ++i) {
        const Node& n = nodes_[i];
        const PassReport& r = report_.passes[i];
        std::string writes, reads;
        for (size_t k = 0; k < n.writes.size(); ++k) {
            const ResourceWrite& w = n.writes[k];
            writes += fmt::format("{}`{}` {}{}", writes.empty() ? "" : ", ",
                                  valueName(n.writeValues[k]), formatName(w.desc.format),
                                  w.persistent()                         ? " (persistent)"
                                  : w.desc.storage == Storage::Transient ? " (transient)"
                                                                         : "");
        }
        for (size_t k = 0; k < n.reads.size(); ++k) {
            const ResourceRead& rd = n.reads[k];
            const std::string name =
                n.readValues[k] < 0 ? std::string(rd.id.name) : valueName(n.readValues[k]);
            reads += std::string(reads.empty() ? "" : ", ") + (rd.optional ? "*`" : "`") + name +
                     (rd.optional ? "`*" : "`");
        }
        std::string why = r.reason;
        for (char& c : why)
            if (c == '|') c = '/';
        s << fmt::format("| {} | `{}` | {} | {} | {}: {} |\n", i + 1, n.pass->name(), writes,
                         reads.empty() ? "-" : reads,
                         r.ran ? "ran" : (r.reused ? "reused" : "skipped"), why);
    }
    return s.str();
}

std::string FrameGraph::dot() const {
    std::ostringstream s;
    s << "digraph frame {\n  rankdir=LR;\n  node [fontname=\"Helvetica\", fontsize=11];\n"
         "  edge [fontname=\"Helvetica\", fontsize=9];\n";
    s << "  import [shape=cds, label=\"import\"];\n  output [shape=doublecircle, label=\"out\"];\n";
    for (size_t i = 0; i < nodes_.size(); ++i) {
        const PassReport& r = report_.passes[i];
        const char* style = r.ran      ? "style=filled, fillcolor=\"#c8e6c9\""
                            : r.reused ? "style=filled, fillcolor=\"#bbdefb\""
                                       : "style=\"filled,dashed\", fillcolor=\"#eeeeee\", "
                                         "fontcolor=\"#777777\"";
        std::string why = r.reason;
        if (why.size() > 48) why = why.substr(0, 45) + "...";
        std::string esc;
        for (char c : why) esc += c == '"' ? std::string("\\\"") : std::string(1, c);
        s << fmt::format("  p{} [shape=box, {}, label=\"{}\\n{}\"];\n", i, style,
                         nodes_[i].pass->name(), esc);
    }
    // One edge per (writer, reader, optional) with the resources as its label.
    for (size_t i = 0; i < nodes_.size(); ++i)
        for (int optional = 0; optional < 2; ++optional) {
            std::vector<std::pair<int, std::vector<int>>> groups;
            for (size_t k = 0; k < nodes_[i].reads.size(); ++k) {
                if (nodes_[i].reads[k].optional != bool(optional)) continue;
                const int v = nodes_[i].readValues[k];
                if (v < 0) continue;  // an optional read nothing writes
                const int w = values_[size_t(v)].writer;
                auto it = std::find_if(groups.begin(), groups.end(),
                                       [&](const auto& g) { return g.first == w; });
                if (it == groups.end()) {
                    groups.push_back({w, {}});
                    it = groups.end() - 1;
                }
                it->second.push_back(v);
            }
            for (const auto& [w, vs] : groups) {
                std::string label;
                for (int v : vs) label += std::string(label.empty() ? "" : "\\n") + valueName(v);
                s << fmt::format("  {} -> p{} [label=\"{}\"{}];\n",
                                 w >= 0 ? "p" + std::to_string(w) : std::string("import"), i, label,
                                 optional ? ", style=dashed" : "");
            }
        }
    for (int o : outputs_) {
        const int v = versions_[size_t(o)].back();
        s << fmt::format("  p{} -> output [label=\"{}\"];\n", values_[size_t(v)].writer,
                         resources_[size_t(o)].name);
    }
    s << "}\n";
    return s.str();
}

int PassResources::declaredRead(Resource r) const {
    const FrameGraph::Node& n = graph_.nodes_[node_];
    for (size_t k = 0; k < n.reads.size(); ++k)
        if (n.reads[k].id == r) return int(k);
    MR_CHECK(false, fmt::format("pass {} reads {}, which its setup() does not declare (add "
                                "b.read or b.readOptional)",
                                n.pass->name(), r.name));
    return -1;  // unreachable: MR_CHECK throws
}

int PassResources::declaredWrite(Resource r) const {
    const FrameGraph::Node& n = graph_.nodes_[node_];
    for (size_t k = 0; k < n.writes.size(); ++k)
        if (n.writes[k].id == r) return int(k);
    MR_CHECK(false, fmt::format("pass {} publishes {}, which its setup() does not declare "
                                "as a write",
                                n.pass->name(), r.name));
    return -1;
}

const gl::Texture& PassResources::texture(Resource r) const {
    const int k = declaredRead(r);
    const int v = graph_.resolvedReads_[node_][size_t(k)];
    const FrameGraph::Slot* s = v >= 0 ? &graph_.current_[size_t(v)] : nullptr;
    MR_CHECK(
        s && s->texture != nullptr,
        fmt::format("pass {} reads {} ({}), which no pass published this frame",
                    graph_.nodes_[node_].pass->name(), r.name,
                    graph_.nodes_[node_].reads[size_t(k)].optional ? "optional: check has() first"
                                                                   : "required"));
    return *s->texture;
}

const gl::Buffer& PassResources::buffer(Resource r) const {
    const int k = declaredRead(r);
    const int v = graph_.resolvedReads_[node_][size_t(k)];
    const FrameGraph::Slot* s = v >= 0 ? &graph_.current_[size_t(v)] : nullptr;
    MR_CHECK(s && s->buffer != nullptr, fmt::format("pass {} reads buffer {}, which no pass "
                                                    "published this frame",
                                                    graph_.nodes_[node_].pass->name(), r.name));
    return *s->buffer;
}

bool PassResources::has(Resource r) const {
    const int v = graph_.resolvedReads_[node_][size_t(declaredRead(r))];
    return v >= 0 && bool(graph_.current_[size_t(v)]);
}

bool PassResources::hasTexture(Resource r) const {
    const int v = graph_.resolvedReads_[node_][size_t(declaredRead(r))];
    return v >= 0 && graph_.current_[size_t(v)].texture != nullptr;
}

const gl::Texture& PassResources::textureOr(Resource r, const gl::Texture& fallback) const {
    return has(r) ? texture(r) : fallback;
}

const gl::Texture& PassResources::target(Resource r) const {
    const int k = declaredWrite(r);
    const int p = graph_.poolOf_[size_t(graph_.nodes_[node_].writeValues[size_t(k)])];
    MR_CHECK(p >= 0, fmt::format("pass {} asks for a target for {}, which it did not declare "
                                 "Storage::Transient",
                                 graph_.nodes_[node_].pass->name(), r.name));
    return graph_.pool_[size_t(p)].texture;
}

void PassResources::publishSlot(Resource r, const FrameGraph::Slot& s) {
    const int k = declaredWrite(r);
    const FrameGraph::Node& n = graph_.nodes_[node_];
    graph_.checkPublished(n, k, s, ctx_);
    const int v = n.writeValues[size_t(k)];
    graph_.current_[size_t(v)] = s;
    graph_.published_[node_].push_back({v, s});
}

void PassResources::publish(Resource r, const gl::Texture& texture) {
    FrameGraph::Slot s;
    s.texture = &texture;
    publishSlot(r, s);
}

void PassResources::publish(Resource r, const gl::Buffer& buffer) {
    FrameGraph::Slot s;
    s.buffer = &buffer;
    publishSlot(r, s);
}

}  // namespace mirage::render
