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
            const int sc = c.gatherScale(), k = std::max(1, o.interleave);
            w = (c.canvasWidth() + sc - 1) / sc, h = (c.canvasHeight() + sc - 1) / sc;
            if (s == SizeRule::GatherTiles) w = (w + k - 1) / k * k, h = (h + k - 1) / k * k;
            return true;
        }
        case SizeRule::ShadowAtlas:
            w = h = o.shadowMapSize;
            layers = std::max(1, c.plan.shadowLayers);
            return true;
        case SizeRule::IsmAtlas:
            w = h = ismTilesPerRow(o.vplCount) * o.ismTileSize;
            return true;
        case SizeRule::CausticMap:
            w = h = o.causticMapSize;
            layers = std::max(1, c.plan.causticLayers);
            return true;
        case SizeRule::Impostor:
        case SizeRule::Vpl:
        case SizeRule::Scene:
            return false;
    }
    return false;
}

std::string joinNames(const std::vector<Resource>& rs) {
    std::string s;
    for (Resource r : rs) s += (s.empty() ? "" : ", ") + std::string(resourceName(r));
    return s;
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

void FrameGraph::importTexture(Resource r, GLenum format, SizeRule size, std::string what) {
    MR_CHECK(!compiled_, "FrameGraph::importTexture after compile()");
    MR_CHECK(!findImport(r), std::string("resource ") + resourceName(r) + " imported twice");
    imports_.push_back({r, format, size, std::move(what), nullptr});
}

RenderPass& FrameGraph::addPass(std::unique_ptr<RenderPass> pass) {
    MR_CHECK(!compiled_, "FrameGraph::addPass after compile()");
    MR_CHECK(pass != nullptr, "FrameGraph::addPass(nullptr)");
    PassBuilder b;
    pass->setup(b);
    Node n;
    n.pass = std::move(pass);
    n.writes = std::move(b.writes_);
    n.reads = std::move(b.reads_);
    nodes_.push_back(std::move(n));
    return *nodes_.back().pass;
}

void FrameGraph::markOutput(Resource r) {
    outputs_.push_back(r);
}

const FrameGraph::Import* FrameGraph::findImport(Resource r) const {
    for (const Import& i : imports_)
        if (i.id == r) return &i;
    return nullptr;
}

void FrameGraph::compile() {
    MR_CHECK(!compiled_, "FrameGraph::compile called twice");
    writer_.fill(-1);
    for (size_t i = 0; i < nodes_.size(); ++i) {
        const Node& n = nodes_[i];
        for (const ResourceWrite& w : n.writes) {
            const int prev = writer_[size_t(w.id)];
            if (prev >= 0)
                throw Error(fmt::format(
                    "frame graph: {} is written by both {} and {}; a resource "
                    "has one writer",
                    resourceName(w.id), nodes_[size_t(prev)].pass->name(), n.pass->name()));
            if (findImport(w.id))
                throw Error(fmt::format("frame graph: {} writes {}, which is imported",
                                        n.pass->name(), resourceName(w.id)));
            writer_[size_t(w.id)] = int(i);
        }
    }
    for (size_t i = 0; i < nodes_.size(); ++i) {
        const Node& n = nodes_[i];
        for (const ResourceRead& r : n.reads) {
            const int w = writer_[size_t(r.id)];
            // An optional read may have no writer in this graph (then it is never available).
            if (findImport(r.id) || (w >= 0 && w < int(i)) || (w < 0 && r.optional)) continue;
            throw Error(fmt::format(
                "frame graph: {} reads {}, which {}", n.pass->name(), resourceName(r.id),
                w < 0 ? "no pass writes and nothing imports"
                      : fmt::format("only {} writes, after it (passes run in the order added)",
                                    nodes_[size_t(w)].pass->name())));
        }
    }
    for (Resource o : outputs_)
        if (writer_[size_t(o)] < 0)
            throw Error(fmt::format("frame graph: output {} has no writer", resourceName(o)));
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
    outputHeld_.assign(nodes_.size(), false);
    report_.passes.assign(nodes_.size(), PassReport{});
    for (size_t i = 0; i < nodes_.size(); ++i) {
        report_.passes[i].name = nodes_[i].pass->name();
        report_.passes[i].reason = "not run yet";
    }
    compiled_ = true;
}

void FrameGraph::setImport(Resource r, const gl::Texture& texture) {
    for (Import& i : imports_)
        if (i.id == r) {
            MR_CHECK(texture.format() == i.format,
                     fmt::format("import {} is {}, declared {}", resourceName(r),
                                 formatName(texture.format()), formatName(i.format)));
            i.texture = &texture;
            return;
        }
    MR_CHECK(false, std::string("setImport: ") + resourceName(r) + " was not declared an import");
}

// Which passes run this frame, and why each does or does not (into report_).
void FrameGraph::plan(FrameContext& ctx, std::vector<int>& run) {
    const size_t n = nodes_.size();
    run.assign(n, 0);
    std::vector<bool> available(kResourceCount, false);
    for (const Import& i : imports_) available[size_t(i.id)] = i.texture != nullptr;
    // Forward: the scene conditions, then the required reads.
    std::vector<std::string> rootCause(n);
    for (size_t i = 0; i < n; ++i) {
        const Node& node = nodes_[i];
        PassReport& rep = report_.passes[i];
        rep = PassReport{};
        rep.name = node.pass->name();
        const PassDecision d = node.pass->decide(ctx);
        rep.reason = rootCause[i] = d.reason;
        if (!d.run) continue;
        const ResourceRead* missing = nullptr;
        for (const ResourceRead& r : node.reads)
            if (!r.optional && !available[size_t(r.id)]) {
                missing = &r;
                break;
            }
        if (missing) {
            const int w = writer_[size_t(missing->id)];
            rep.reason = w < 0 ? fmt::format("needs {}, which is not imported this frame",
                                             resourceName(missing->id))
                               : fmt::format("needs {} ({}: {})", resourceName(missing->id),
                                             nodes_[size_t(w)].pass->name(), rootCause[size_t(w)]);
            rootCause[i] = w < 0 ? rep.reason : rootCause[size_t(w)];
            continue;
        }
        run[i] = 1;
        for (const ResourceWrite& wr : node.writes) available[size_t(wr.id)] = true;
    }
    // Backward from the outputs: a pass runs only if a running pass (or the output) reads it.
    std::vector<bool> needed(kResourceCount, false);
    for (Resource o : outputs_) needed[size_t(o)] = true;
    for (size_t k = n; k-- > 0;) {
        if (!run[k]) continue;
        const Node& node = nodes_[k];
        std::vector<Resource> writes;
        bool read = false;
        for (const ResourceWrite& w : node.writes) {
            writes.push_back(w.id);
            read = read || needed[size_t(w.id)];
        }
        if (!read) {
            run[k] = 0;
            report_.passes[k].reason = "culled: no pass this frame reads " + joinNames(writes);
            continue;
        }
        for (const ResourceRead& r : node.reads)
            if (!r.optional || available[size_t(r.id)]) needed[size_t(r.id)] = true;
    }
}

const FrameReport& FrameGraph::execute(FrameContext& ctx, const std::string& staticKey) {
    MR_CHECK(compiled_, "FrameGraph::execute before compile()");
    current_.fill(Slot{});
    for (const Import& i : imports_)
        if (i.texture) current_[size_t(i.id)].texture = i.texture;
    if (staticKey != staticKey_ || staticOutputValid_.size() != nodes_.size()) {
        staticKey_ = staticKey;
        staticOutputValid_.assign(nodes_.size(), false);
    }
    std::vector<int> run;
    plan(ctx, run);
    report_.totalGpuMs = 0.0;
    const RendererOptions& o = ctx.options;
    using Clock = std::chrono::steady_clock;
    const auto msSince = [](Clock::time_point t) {
        return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
    };
    const Clock::time_point frameStart = Clock::now();
    syncedMs_.assign(nodes_.size(), 0.0);
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
            for (const auto& [res, slot] : published_[i]) current_[size_t(res)] = slot;
            rep.reused = true;
            rep.reason = "reused: " + rep.reason;
            continue;
        }
        if (p.cameraIndependent() && o.reuseStaticPasses && staticOutputValid_[i]) {
            for (const auto& [res, slot] : published_[i]) current_[size_t(res)] = slot;
            rep.reused = true;
            rep.reason = "reused: scene, lights and plan unchanged (" + rep.reason + ")";
            continue;
        }
        p.resize(ctx);  // no-op unless the plan's sizes changed (shadow layers, VPL count)
        published_[i].clear();
        PassResources view(*this, i, ctx);
        if (o.syncPasses) {
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
        staticOutputValid_[i] = p.cameraIndependent();
        outputHeld_[i] = true;
    }
    for (size_t i = 0; i < nodes_.size(); ++i) {
        if (!report_.passes[i].ran) continue;
        double ms = syncedMs_[i];
        if (!o.syncPasses) {
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
    return bool(current_[size_t(r)]);
}

const gl::Texture& FrameGraph::texture(Resource r) const {
    const Slot& s = current_[size_t(r)];
    if (!s.texture)
        throw Error(std::string("buffer ") + resourceName(r) + " was not produced this frame");
    return *s.texture;
}

const gl::Buffer& FrameGraph::buffer(Resource r) const {
    const Slot& s = current_[size_t(r)];
    if (!s.buffer)
        throw Error(std::string("buffer ") + resourceName(r) + " was not produced this frame");
    return *s.buffer;
}

std::vector<std::string> FrameGraph::passNames() const {
    std::vector<std::string> names;
    for (const Node& n : nodes_) names.push_back(n.pass->name());
    return names;
}

void FrameGraph::checkPublished(const Node& n, Resource r, const Slot& s,
                                const FrameContext& ctx) const {
    const ResourceWrite* w = nullptr;
    for (const ResourceWrite& x : n.writes)
        if (x.id == r) w = &x;
    MR_CHECK(w != nullptr, fmt::format("pass {} publishes {}, which its setup() does not declare "
                                       "as a write",
                                       n.pass->name(), resourceName(r)));
    MR_CHECK(
        w->buffer == (s.buffer != nullptr),
        fmt::format("pass {} publishes {} as a {}, declared a {}", n.pass->name(), resourceName(r),
                    s.buffer ? "buffer" : "texture", w->buffer ? "buffer" : "texture"));
    if (!s.texture) return;
    // An alias of one of the pass's reads (ShadowMapsReal = ShadowMaps) has that one's format.
    MR_CHECK(s.texture->format() == w->format,
             fmt::format("pass {} publishes {} as {}, declared {}", n.pass->name(), resourceName(r),
                         formatName(s.texture->format()), formatName(w->format)));
    int ew = 0, eh = 0, el = 1;
    if (expectedSize(w->size, ctx, ew, eh, el))
        MR_CHECK(
            s.texture->width() == ew && s.texture->height() == eh && s.texture->layers() == el,
            fmt::format("pass {} publishes {} at {}x{}x{}, but its size rule ({}) gives "
                        "{}x{}x{}",
                        n.pass->name(), resourceName(r), s.texture->width(), s.texture->height(),
                        s.texture->layers(), sizeRuleName(w->size), ew, eh, el));
}

std::string FrameGraph::describe() const {
    std::ostringstream s;
    s << "imports:";
    for (const Import& i : imports_)
        s << fmt::format(" {} ({}, {})", resourceName(i.id), formatName(i.format), i.what);
    s << "\noutputs:";
    for (Resource o : outputs_) s << " " << resourceName(o);
    s << "\n";
    for (size_t i = 0; i < nodes_.size(); ++i) {
        const Node& n = nodes_[i];
        const PassReport& r = report_.passes[i];
        s << fmt::format("\n{:>2} {:<10} {:<7} {}\n", i + 1, n.pass->name(),
                         r.ran ? "ran" : (r.reused ? "reused" : "skipped"), r.reason);
        for (const ResourceWrite& w : n.writes)
            s << fmt::format("     writes {:<24} {:<12} {}{}\n", resourceName(w.id),
                             formatName(w.format), sizeRuleName(w.size),
                             w.persistent ? ", persistent" : "");
        for (const ResourceRead& rd : n.reads) {
            const int w = writer_[size_t(rd.id)];
            s << fmt::format("     reads  {:<24} {:<12} from {}\n", resourceName(rd.id),
                             rd.optional ? "(optional)" : "",
                             w >= 0              ? nodes_[size_t(w)].pass->name()
                             : findImport(rd.id) ? "import"
                                                 : "nothing in this graph");
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
        for (const ResourceWrite& w : n.writes)
            writes += fmt::format("{}`{}` {}{}", writes.empty() ? "" : ", ", resourceName(w.id),
                                  formatName(w.format), w.persistent ? " (persistent)" : "");
        for (const ResourceRead& rd : n.reads)
            reads += std::string(reads.empty() ? "" : ", ") + (rd.optional ? "*`" : "`") +
                     resourceName(rd.id) + (rd.optional ? "`*" : "`");
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
            std::vector<std::pair<int, std::vector<Resource>>> groups;
            for (const ResourceRead& rd : nodes_[i].reads) {
                if (rd.optional != bool(optional)) continue;
                const int w = writer_[size_t(rd.id)];
                if (w < 0 && !findImport(rd.id)) continue;  // an optional read nothing writes
                auto it = std::find_if(groups.begin(), groups.end(),
                                       [&](const auto& g) { return g.first == w; });
                if (it == groups.end()) {
                    groups.push_back({w, {}});
                    it = groups.end() - 1;
                }
                it->second.push_back(rd.id);
            }
            for (const auto& [w, rs] : groups) {
                std::string label;
                for (Resource r : rs)
                    label += std::string(label.empty() ? "" : "\\n") + resourceName(r);
                s << fmt::format("  {} -> p{} [label=\"{}\"{}];\n",
                                 w >= 0 ? "p" + std::to_string(w) : std::string("import"), i, label,
                                 optional ? ", style=dashed" : "");
            }
        }
    for (Resource o : outputs_)
        s << fmt::format("  p{} -> output [label=\"{}\"];\n", writer_[size_t(o)], resourceName(o));
    s << "}\n";
    return s.str();
}

const ResourceRead& PassResources::declaredRead(Resource r) const {
    const FrameGraph::Node& n = graph_.nodes_[node_];
    for (const ResourceRead& x : n.reads)
        if (x.id == r) return x;
    MR_CHECK(false, fmt::format("pass {} reads {}, which its setup() does not declare (add "
                                "b.read or b.readOptional)",
                                n.pass->name(), resourceName(r)));
    return n.reads.front();  // unreachable: MR_CHECK throws
}

const gl::Texture& PassResources::texture(Resource r) const {
    const ResourceRead& d = declaredRead(r);
    const FrameGraph::Slot& s = graph_.current_[size_t(r)];
    MR_CHECK(s.texture != nullptr,
             fmt::format("pass {} reads {} ({}), which no pass published this frame",
                         graph_.nodes_[node_].pass->name(), resourceName(r),
                         d.optional ? "optional: check has() first" : "required"));
    return *s.texture;
}

const gl::Buffer& PassResources::buffer(Resource r) const {
    declaredRead(r);
    const FrameGraph::Slot& s = graph_.current_[size_t(r)];
    MR_CHECK(s.buffer != nullptr, fmt::format("pass {} reads buffer {}, which no pass published "
                                              "this frame",
                                              graph_.nodes_[node_].pass->name(), resourceName(r)));
    return *s.buffer;
}

bool PassResources::has(Resource r) const {
    declaredRead(r);
    return bool(graph_.current_[size_t(r)]);
}

const gl::Texture& PassResources::textureOr(Resource r, const gl::Texture& fallback) const {
    return has(r) ? texture(r) : fallback;
}

void PassResources::publishSlot(Resource r, const FrameGraph::Slot& s) {
    graph_.checkPublished(graph_.nodes_[node_], r, s, ctx_);
    graph_.current_[size_t(r)] = s;
    graph_.published_[node_].push_back({r, s});
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
