// The frame graph (render/FrameGraph.h): set-up checks (every read has an earlier writer or an
// import, one writer per resource), the per-pass resource view (a pass that looks up or publishes
// a resource it did not declare fails loudly; a real pass with a deliberately dropped read fails),
// publish checks (format, size rule), and per-frame culling with its reasons.
#include <gtest/gtest.h>

#include <chrono>
#include <iostream>
#include <thread>

#include <functional>
#include <memory>
#include <string>

#include "core/Error.h"
#include "core/gl/Context.h"
#include "render/FrameGraph.h"
#include "render/FrameImports.h"
#include "render/Renderer.h"
#include "render/passes/composite/CompositePass.h"
#include "render/passes/direct/DirectLightPass.h"
#include "render/passes/environment/EnvironmentPass.h"
#include "render/passes/gbuffer/GBufferPass.h"
#include "render/passes/indirect/IndirectLightPass.h"
#include "render/passes/ism/IsmPass.h"
#include "render/passes/shadow/ShadowPass.h"
#include "render/passes/specular/SpecularLightPass.h"
#include "render/passes/vpl/VplPass.h"
#include "testscenes/RenderTestScenes.h"

namespace mirage::render {
namespace {

// A real pass with one of its declared reads dropped from its setup (everything else forwarded):
// the pass still binds that resource in execute(), which the graph must refuse.
class DropRead final : public RenderPass {
public:
    DropRead(std::unique_ptr<RenderPass> inner, Resource dropped)
        : inner_(std::move(inner)), dropped_(dropped) {}
    const char* name() const override { return inner_->name(); }
    void setup(PassBuilder& b) const override {
        PassBuilder all;  // records the inner pass's declarations, replayed without `dropped_`
        inner_->setup(all);
        for (const ResourceRead& r : all.reads()) {
            bool modified = false;
            for (const ResourceWrite& w : all.writes())
                modified = modified || (w.modifies && w.id == r.id);
            if (r.id == dropped_ || modified) continue;
            r.optional ? b.readOptional(r.id) : b.read(r.id);
        }
        for (const ResourceWrite& w : all.writes()) {
            if (w.buffer)
                b.createBuffer(w.id, w.desc.size, w.persistent());
            else if (w.modifies)
                b.modify(w.id, w.desc);
            else
                b.create(w.id, w.desc);
        }
    }
    PassDecision decide(const FrameContext& ctx) const override { return inner_->decide(ctx); }
    void resize(const FrameContext& ctx) override { inner_->resize(ctx); }
    void execute(FrameContext& ctx, PassResources& res) override { inner_->execute(ctx, res); }

private:
    std::unique_ptr<RenderPass> inner_;
    Resource dropped_;
};

// A pass made of declarations: writes canvas-size RGBA16F textures (or what `publishAs` says),
// reads what it is told, and looks up `lookUp` in execute().
struct TestPassSpec {
    std::string name = "test";
    std::vector<Resource> writes{}, reads{}, optionalReads{};
    std::vector<Resource> transient{};         // created Storage::Transient (the graph allocates)
    std::vector<Resource> modifies{};          // new versions of earlier passes' resources
    std::vector<TextureHandle> readHandles{};  // reads of a named version
    bool run = true;
    std::string reason = "test condition";
    std::vector<Resource> lookUp{};        // looked up in execute() (declared or not)
    std::vector<Resource> publishExtra{};  // published in execute() without a declaration
    GLenum publishFormat = GL_RGBA16F;     // format of the published textures
    int cpuMs = 0;                         // execute() sleeps this long
    bool cameraIndependent = false;        // RenderPass::cameraIndependent
    bool staticEachFrame = true;           // RenderPass::staticThisFrame
};

class TestPass final : public RenderPass {
public:
    explicit TestPass(TestPassSpec s) : s_(std::move(s)) {}
    const char* name() const override { return s_.name.c_str(); }
    void setup(PassBuilder& b) const override {
        for (Resource r : s_.reads) b.read(r);
        for (Resource r : s_.optionalReads) b.readOptional(r);
        for (const TextureHandle& h : s_.readHandles) b.read(h);
        for (Resource r : s_.writes)
            b.create(r, {GL_RGBA16F, r == kComposite ? SizeRule::Camera : SizeRule::Canvas,
                         Storage::PassOwned});
        for (Resource r : s_.transient) b.create(r, {GL_RGBA16F, SizeRule::Canvas});
        for (Resource r : s_.modifies)
            b.modify(r, {GL_RGBA16F, SizeRule::Canvas, Storage::PassOwned});
    }
    PassDecision decide(const FrameContext&) const override { return {s_.run, s_.reason}; }
    bool cameraIndependent() const override { return s_.cameraIndependent; }
    bool staticThisFrame(const FrameContext&) const override { return s_.staticEachFrame; }
    void resize(const FrameContext& ctx) override {
        if (!tex_.id()) {
            canvas_ = gl::Texture::create2D("test canvas", ctx.canvasWidth(), ctx.canvasHeight(),
                                            s_.publishFormat);
            camera_ = gl::Texture::create2D("test camera", ctx.projection.camera.width,
                                            ctx.projection.camera.height, s_.publishFormat);
            tex_ = gl::Texture::create2D("test marker", 1, 1, GL_RGBA8);
        }
    }
    void execute(FrameContext&, PassResources& res) override {
        ++runs;
        if (s_.cpuMs > 0) std::this_thread::sleep_for(std::chrono::milliseconds(s_.cpuMs));
        for (Resource r : s_.lookUp) (void)res.texture(r);
        for (Resource r : s_.writes) res.publish(r, r == kComposite ? camera_ : canvas_);
        for (Resource r : s_.modifies) res.publish(r, canvas_);
        for (Resource r : s_.transient) targets.push_back(res.target(r).id());
        for (Resource r : s_.publishExtra) res.publish(r, canvas_);
    }
    int runs = 0;
    std::vector<GLuint> targets;  // the transient textures the graph gave it, per run

private:
    TestPassSpec s_;
    gl::Texture canvas_, camera_, tex_;
};

class FrameGraphTest : public ::testing::Test {
protected:
    FrameGraphTest() : context_(gl::Context::headless()) {
        const int m = test::addMaterial(scene_, glm::vec3(0.5f));
        test::addFloor(scene_, "floor", 0.0f, 2.0f, m, Origin::Real);
        gpu_ = std::make_unique<GpuScene>(scene_, 1024);
        projection_ = CameraProjection::make(test::smallCamera(32, 24, 30.0));
        ctx_ = std::make_unique<FrameContext>(*gpu_, projection_, options_);
        camera_ = gl::Texture::create2D("camera", 32, 24, GL_SRGB8_ALPHA8);
    }
    TestPass& add(FrameGraph& g, TestPassSpec s) {
        return static_cast<TestPass&>(g.addPass(std::make_unique<TestPass>(std::move(s))));
    }
    static std::string errorOf(const std::function<void()>& f) {
        try {
            f();
        } catch (const std::exception& e) {
            return e.what();
        }
        return "";
    }
    gl::Context context_;
    Scene scene_;
    RendererOptions options_;
    std::unique_ptr<GpuScene> gpu_;
    CameraProjection projection_;
    std::unique_ptr<FrameContext> ctx_;
    gl::Texture camera_;
};

TEST_F(FrameGraphTest, CompileRejectsAReadWithoutWriterOrImport) {
    FrameGraph g;
    add(g, {.name = "a", .writes = {kComposite}, .reads = {kLRv}});
    g.markOutput(kComposite);
    const std::string e = errorOf([&] { g.compile(); });
    EXPECT_NE(e.find("a reads LRv, which no pass writes and nothing imports"), std::string::npos)
        << e;
}

TEST_F(FrameGraphTest, CompileRejectsReadsBeforeTheWriterAndTwoWriters) {
    {
        FrameGraph g;
        add(g, {.name = "reader", .writes = {kComposite}, .reads = {kLRv}});
        add(g, {.name = "writer", .writes = {kLRv}});
        g.markOutput(kComposite);
        const std::string e = errorOf([&] { g.compile(); });
        EXPECT_NE(e.find("only writer writes, after it"), std::string::npos) << e;
    }
    {
        FrameGraph g;  // a second pass that writes LRv must say it modifies it
        add(g, {.name = "one", .writes = {kLRv}});
        const std::string e = errorOf([&] {
            add(g, {.name = "two", .writes = {kLRv, kComposite}});
        });
        EXPECT_NE(e.find("LRv is created by both one and two"), std::string::npos) << e;
    }
    {
        FrameGraph g;  // the same graph, well formed, compiles
        add(g, {.name = "writer", .writes = {kLRv}});
        add(g, {.name = "reader", .writes = {kComposite}, .reads = {kLRv}});
        g.markOutput(kComposite);
        EXPECT_NO_THROW(g.compile());
    }
}

// The view hands a pass only what it declared: looking up anything else throws, even when an
// earlier pass published it this frame.
TEST_F(FrameGraphTest, LookingUpAnUndeclaredResourceFails) {
    FrameGraph g;
    add(g, {.name = "writer", .writes = {kLRv, kLR}});
    add(g, {.name = "reader", .writes = {kComposite}, .reads = {kLRv}, .lookUp = {kLRv, kLR}});
    g.markOutput(kComposite);
    g.compile();
    const std::string e = errorOf([&] { g.execute(*ctx_, ""); });
    EXPECT_NE(e.find("pass reader reads LR, which its setup() does not declare"), std::string::npos)
        << e;

    FrameGraph ok;  // declared: runs
    add(ok, {.name = "writer", .writes = {kLRv, kLR}});
    TestPass& reader = add(
        ok,
        {.name = "reader", .writes = {kComposite}, .reads = {kLRv, kLR}, .lookUp = {kLRv, kLR}});
    ok.markOutput(kComposite);
    ok.compile();
    EXPECT_NO_THROW(ok.execute(*ctx_, ""));
    EXPECT_EQ(reader.runs, 1);
}

TEST_F(FrameGraphTest, PublishingAnUndeclaredOrMisdeclaredResourceFails) {
    {
        FrameGraph g;
        add(g, {.name = "sneaky", .writes = {kComposite}, .publishExtra = {kLR}});
        g.markOutput(kComposite);
        g.compile();
        const std::string e = errorOf([&] { g.execute(*ctx_, ""); });
        EXPECT_NE(e.find("sneaky publishes LR, which its setup() does not declare"),
                  std::string::npos)
            << e;
    }
    {
        FrameGraph g;  // declared RGBA16F, publishes RGBA32F
        add(g, {.name = "wrong", .writes = {kComposite}, .publishFormat = GL_RGBA32F});
        g.markOutput(kComposite);
        g.compile();
        const std::string e = errorOf([&] { g.execute(*ctx_, ""); });
        EXPECT_NE(e.find("wrong publishes Composite as RGBA32F, declared RGBA16F"),
                  std::string::npos)
            << e;
    }
}

// A real pass (direct light) whose setup drops its G-buffer normal read fails when it binds the
// normal; the same graph with the pass as it is runs.
TEST_F(FrameGraphTest, RealPassWithAMissingReadFails) {
    for (const bool drop : {true, false}) {
        FrameGraph g;
        g.importTexture(kCameraImage, GL_SRGB8_ALPHA8, SizeRule::Camera, "camera");
        g.importTexture(kSceneEnvironmentMap, GL_RGBA16F, SizeRule::Scene, "env");
        g.importTexture(kEnvironmentCamera, GL_SRGB8_ALPHA8, SizeRule::Scene, "env cam");
        g.addPass(std::make_unique<EnvironmentPass>());  // the direct pass reads its SH9
        g.addPass(std::make_unique<GBufferPass>());
        auto direct = std::make_unique<DirectLightPass>(*gpu_);
        if (drop)
            g.addPass(std::make_unique<DropRead>(std::move(direct), kGBufferNormal));
        else
            g.addPass(std::move(direct));
        g.addPass(std::make_unique<CompositePass>());
        g.markOutput(kComposite);
        g.markOutput(kCompositeSrgb);
        g.compile();
        g.setImport(kCameraImage, camera_);
        g.setImport(kSceneEnvironmentMap, gpu_->environmentMap());
        const std::string e = errorOf([&] { g.execute(*ctx_, ""); });
        if (drop) {
            EXPECT_NE(e.find("pass direct reads GBufferNormal, which its setup() does not "
                             "declare"),
                      std::string::npos)
                << e;
        } else {
            EXPECT_EQ(e, "");
            EXPECT_TRUE(g.lastReport().ran("direct")) << g.lastReport().summary();
        }
    }
}

// Culling: a pass whose required read is not written this frame is skipped with the writer's
// reason; a pass no running pass reads is culled; optional reads do not keep a skipped pass.
TEST_F(FrameGraphTest, CullsFromTheOutputsAndSaysWhy) {
    FrameGraph g;
    TestPass& off = add(
        g, {.name = "off", .writes = {kVpls}, .run = false, .reason = "no light reaches anything"});
    TestPass& dependent = add(g, {.name = "dependent", .writes = {kIndirectRv}, .reads = {kVpls}});
    TestPass& unread = add(g, {.name = "unread", .writes = {kLenv}});
    TestPass& used = add(g, {.name = "used", .writes = {kDirectRv}});
    TestPass& last =
        add(g, {.name = "last", .writes = {kComposite}, .optionalReads = {kIndirectRv, kDirectRv}});
    g.markOutput(kComposite);
    g.compile();
    const FrameReport& rep = g.execute(*ctx_, "");
    EXPECT_EQ(off.runs, 0);
    EXPECT_EQ(dependent.runs, 0);
    EXPECT_EQ(unread.runs, 0);
    EXPECT_EQ(used.runs, 1);
    EXPECT_EQ(last.runs, 1);
    EXPECT_EQ(rep.passes[0].reason, "no light reaches anything");
    EXPECT_EQ(rep.passes[1].reason, "needs Vpls (off: no light reaches anything)");
    EXPECT_EQ(rep.passes[2].reason, "culled: no pass this frame reads Lenv");
    EXPECT_EQ(g.passNames(),
              (std::vector<std::string>{"off", "dependent", "unread", "used", "last"}));
    EXPECT_NE(g.describe().find("reads  Vpls"), std::string::npos) << g.describe();
    EXPECT_NE(g.dot().find("p0 -> p1 [label=\"Vpls\"]"), std::string::npos) << g.dot();
}

// Camera-independent passes are reused while the static key holds, except one that is not static
// this frame (the VPLs rotated every frame) and every camera-independent pass that reads what it
// wrote (the imperfect shadow maps of those VPLs); one that reads only reused outputs stays
// reused.
TEST_F(FrameGraphTest, ARerunCameraIndependentPassRerunsItsCameraIndependentReaders) {
    for (bool sourceStatic : {true, false}) {
        FrameGraph g;
        TestPass& rsm = add(g, {.name = "rsm", .writes = {kRsmFlux}, .cameraIndependent = true});
        TestPass& vpl = add(g, {.name = "vpl",
                                .writes = {kVpls},
                                .reads = {kRsmFlux},
                                .cameraIndependent = true,
                                .staticEachFrame = sourceStatic});
        TestPass& ism = add(g, {.name = "ism",
                                .writes = {kImperfectShadowMaps},
                                .reads = {kVpls},
                                .cameraIndependent = true});
        TestPass& shadowed = add(g, {.name = "shadow user",
                                     .writes = {kLenv},
                                     .reads = {kRsmFlux},
                                     .cameraIndependent = true});
        TestPass& last = add(
            g, {.name = "last", .writes = {kComposite}, .reads = {kImperfectShadowMaps, kLenv}});
        g.markOutput(kComposite);
        g.compile();
        for (int frame = 0; frame < 3; ++frame) g.execute(*ctx_, "static");
        EXPECT_EQ(rsm.runs, 1) << sourceStatic;
        EXPECT_EQ(vpl.runs, sourceStatic ? 1 : 3);
        EXPECT_EQ(ism.runs, sourceStatic ? 1 : 3) << "a reader of rewritten VPLs runs again";
        EXPECT_EQ(shadowed.runs, 1) << sourceStatic;
        EXPECT_EQ(last.runs, 3);
    }
}

// Versioned writes: a pass that modifies a resource writes its next version; readers declared
// after it read that version, and when it is skipped the version before (passed through).
TEST_F(FrameGraphTest, AModifierWritesTheNextVersionAndIsPassedThroughWhenSkipped) {
    for (const bool filterRuns : {true, false}) {
        FrameGraph g;
        TestPass& sharp = add(g, {.name = "sharp", .writes = {kLenv}});
        TestPass& filter =
            add(g, {.name = "filter", .modifies = {kLenv}, .run = filterRuns, .reason = "rough"});
        TestPass& last =
            add(g, {.name = "last", .writes = {kComposite}, .reads = {kLenv}, .lookUp = {kLenv}});
        g.markOutput(kComposite);
        g.compile();
        const FrameReport& rep = g.execute(*ctx_, "");
        EXPECT_EQ(sharp.runs, 1) << rep.summary();
        EXPECT_EQ(filter.runs, filterRuns ? 1 : 0);
        EXPECT_EQ(last.runs, 1);
        EXPECT_NE(g.describe().find("modifies Lenv v1"), std::string::npos) << g.describe();
        EXPECT_NE(g.describe().find("reads  Lenv v1"), std::string::npos) << g.describe();
    }
    {
        FrameGraph g;  // a modifier nobody reads after is culled; its input's writer too
        add(g, {.name = "sharp", .writes = {kLenv}});
        add(g, {.name = "filter", .modifies = {kLenv}});
        add(g, {.name = "last", .writes = {kComposite}});
        g.markOutput(kComposite);
        g.compile();
        const FrameReport& rep = g.execute(*ctx_, "");
        EXPECT_EQ(rep.passes[1].reason, "culled: no pass this frame reads Lenv v1");
        EXPECT_FALSE(rep.ran("sharp"));
    }
}

// Reading a version older than the newest (a handle taken before another pass modified the
// resource) is refused when the reader is added: that version is gone by the time it runs.
TEST_F(FrameGraphTest, ReadingAModifiedResourceAtAnOlderVersionFails) {
    FrameGraph g;
    add(g, {.name = "sharp", .writes = {kLenv}});
    add(g, {.name = "filter", .modifies = {kLenv}});
    const std::string e = errorOf([&] {
        add(g, {.name = "stale", .writes = {kComposite}, .readHandles = {TextureHandle{kLenv, 0}}});
    });
    EXPECT_NE(e.find("stale reads Lenv version 0, but filter wrote version 1 before it"),
              std::string::npos)
        << e;
    FrameGraph ok;  // the newest handle is accepted
    add(ok, {.name = "sharp", .writes = {kLenv}});
    add(ok, {.name = "filter", .modifies = {kLenv}});
    EXPECT_NO_THROW(add(
        ok, {.name = "fresh", .writes = {kComposite}, .readHandles = {TextureHandle{kLenv, 1}}}));
}

// The graph allocates transient textures from their descriptors: two whose lifetimes (writer to
// last reader) do not overlap share one texture, overlapping ones do not; the first one's
// contents are gone after the frame, which a readback says.
TEST_F(FrameGraphTest, TransientTexturesShareMemoryOnlyWhenTheirLifetimesDoNotOverlap) {
    FrameGraph g;
    TestPass& p1 = add(g, {.name = "p1", .transient = {kIndirectRv}});
    TestPass& p2 = add(g, {.name = "p2", .reads = {kIndirectRv}, .transient = {kIndirectR}});
    TestPass& p3 = add(g, {.name = "p3", .reads = {kIndirectR}, .transient = {kDirectRv}});
    add(g, {.name = "p4", .writes = {kComposite}, .reads = {kDirectRv}});
    g.markOutput(kComposite);
    g.compile();
    for (int frame = 0; frame < 2; ++frame) {
        g.execute(*ctx_, "");
        const GLuint a = p1.targets.back(), b = p2.targets.back(), c = p3.targets.back();
        EXPECT_EQ(a, g.transientTextureId(kIndirectRv));
        EXPECT_NE(a, b);  // IndirectRv is read while IndirectR is written
        EXPECT_NE(b, c);
        EXPECT_EQ(a, c);  // IndirectRv's last reader (p2) ran before DirectRv's writer (p3)
        const FrameGraph::TransientMemory& m = g.transientMemory();
        const size_t one = size_t(ctx_->canvasWidth()) * size_t(ctx_->canvasHeight()) * 8;
        EXPECT_EQ(m.requestedBytes, 3 * one);
        EXPECT_EQ(m.allocatedBytes, 2 * one);
        EXPECT_EQ(m.textures, 2);
    }
    EXPECT_EQ(p1.targets[0], p1.targets[1]);  // a stable assignment from frame to frame
    const std::string e = errorOf([&] { (void)g.texture(kIndirectRv); });
    EXPECT_NE(e.find("IndirectRv was transient and a later resource of the frame reused"),
              std::string::npos)
        << e;
    EXPECT_NO_THROW((void)g.texture(kDirectRv));

    FrameGraph overlap;  // IndirectRv read by the last pass: alive while both others are written
    TestPass& q1 = add(overlap, {.name = "q1", .transient = {kIndirectRv}});
    TestPass& q2 = add(overlap, {.name = "q2", .transient = {kIndirectR}});
    TestPass& q3 = add(overlap, {.name = "q3", .reads = {kIndirectR}, .transient = {kDirectRv}});
    add(overlap, {.name = "q4", .writes = {kComposite}, .reads = {kDirectRv, kIndirectRv}});
    overlap.markOutput(kComposite);
    overlap.compile();
    overlap.execute(*ctx_, "");
    EXPECT_NE(q1.targets.back(), q2.targets.back());
    EXPECT_NE(q1.targets.back(), q3.targets.back());
    EXPECT_NE(q2.targets.back(), q3.targets.back());
    EXPECT_EQ(overlap.transientMemory().textures, 3);
}

// With syncPasses a pass's time is the wall time between a glFinish before and after it: all it
// costs on llvmpipe, also work GL_TIME_ELAPSED does not see (compute dispatches there; here the
// pass sleeps on the CPU, which the GPU timer does not see either: the unsynchronised report
// shows the difference).
TEST_F(FrameGraphTest, SynchronisedPassTimeIsTheWholePass) {
    FrameGraph g;
    add(g, {.name = "slow", .writes = {kComposite}, .cpuMs = 40});
    g.markOutput(kComposite);
    g.compile();
    options_.graph.syncPasses = true;
    const double synced = g.execute(*ctx_, "").passes[0].gpuMs;
    options_.graph.syncPasses = false;
    const double timed = g.execute(*ctx_, "").passes[0].gpuMs;
    std::cout << "a pass sleeping 40 ms: " << synced << " ms synchronised, " << timed
              << " ms by GL_TIME_ELAPSED\n";
    EXPECT_GE(synced, 39.0);
    EXPECT_LT(synced, 2000.0);
    EXPECT_GE(timed, 0.0);
    EXPECT_LT(timed, 20.0);
}

// The renderer's own graph: every pass in the report, in the graph's order.
TEST_F(FrameGraphTest, RendererReportsEveryPassOfItsGraph) {
    Renderer r(scene_, test::smallCamera(32, 24, 30.0));
    const FrameReport& rep = r.render({test::lookAtPose({0, 1, 1.5}, {0, 0, 0}), {}, true});
    ASSERT_EQ(rep.passes.size(), r.passNames().size());
    for (size_t i = 0; i < rep.passes.size(); ++i) EXPECT_EQ(rep.passes[i].name, r.passNames()[i]);
    EXPECT_TRUE(rep.ran("gbuffer"));
    EXPECT_TRUE(rep.ran("composite"));
    EXPECT_FALSE(rep.ran("impostor"));
    EXPECT_NE(r.graph().describe().find("writes GBufferPosition"), std::string::npos);
}

}  // namespace
}  // namespace mirage::render
