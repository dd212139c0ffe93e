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
#include "render/Renderer.h"
#include "render/passes/composite/CompositePass.h"
#include "render/passes/direct/DirectLightPass.h"
#include "render/passes/environment/EnvironmentPass.h"
#include "render/passes/gbuffer/GBufferPass.h"
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
        PassBuilder all;
        inner_->setup(all);
        for (const ResourceWrite& w : all.writes()) {
            if (w.buffer)
                b.writeBuffer(w.id, w.size, w.persistent);
            else
                b.write(w.id, w.format, w.size, w.persistent);
        }
        for (const ResourceRead& r : all.reads()) {
            if (r.id == dropped_) continue;
            r.optional ? b.readOptional(r.id) : b.read(r.id);
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
    bool run = true;
    std::string reason = "test condition";
    std::vector<Resource> lookUp{};        // looked up in execute() (declared or not)
    std::vector<Resource> publishExtra{};  // published in execute() without a declaration
    GLenum publishFormat = GL_RGBA16F;     // format of the published textures
    int cpuMs = 0;                         // execute() sleeps this long
};

class TestPass final : public RenderPass {
public:
    explicit TestPass(TestPassSpec s) : s_(std::move(s)) {}
    const char* name() const override { return s_.name.c_str(); }
    void setup(PassBuilder& b) const override {
        for (Resource r : s_.writes)
            b.write(r, GL_RGBA16F, r == Resource::Composite ? SizeRule::Camera : SizeRule::Canvas);
        for (Resource r : s_.reads) b.read(r);
        for (Resource r : s_.optionalReads) b.readOptional(r);
    }
    PassDecision decide(const FrameContext&) const override { return {s_.run, s_.reason}; }
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
        for (Resource r : s_.writes) res.publish(r, r == Resource::Composite ? camera_ : canvas_);
        for (Resource r : s_.publishExtra) res.publish(r, canvas_);
    }
    int runs = 0;

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
    add(g, {.name = "a", .writes = {Resource::Composite}, .reads = {Resource::LRv}});
    g.markOutput(Resource::Composite);
    const std::string e = errorOf([&] { g.compile(); });
    EXPECT_NE(e.find("a reads LRv, which no pass writes and nothing imports"), std::string::npos)
        << e;
}

TEST_F(FrameGraphTest, CompileRejectsReadsBeforeTheWriterAndTwoWriters) {
    {
        FrameGraph g;
        add(g, {.name = "reader", .writes = {Resource::Composite}, .reads = {Resource::LRv}});
        add(g, {.name = "writer", .writes = {Resource::LRv}});
        g.markOutput(Resource::Composite);
        const std::string e = errorOf([&] { g.compile(); });
        EXPECT_NE(e.find("only writer writes, after it"), std::string::npos) << e;
    }
    {
        FrameGraph g;
        add(g, {.name = "one", .writes = {Resource::LRv}});
        add(g, {.name = "two", .writes = {Resource::LRv, Resource::Composite}});
        g.markOutput(Resource::Composite);
        const std::string e = errorOf([&] { g.compile(); });
        EXPECT_NE(e.find("LRv is written by both one and two"), std::string::npos) << e;
    }
    {
        FrameGraph g;  // the same graph, well formed, compiles
        add(g, {.name = "writer", .writes = {Resource::LRv}});
        add(g, {.name = "reader", .writes = {Resource::Composite}, .reads = {Resource::LRv}});
        g.markOutput(Resource::Composite);
        EXPECT_NO_THROW(g.compile());
    }
}

// The view hands a pass only what it declared: looking up anything else throws, even when an
// earlier pass published it this frame.
TEST_F(FrameGraphTest, LookingUpAnUndeclaredResourceFails) {
    FrameGraph g;
    add(g, {.name = "writer", .writes = {Resource::LRv, Resource::LR}});
    add(g, {.name = "reader",
            .writes = {Resource::Composite},
            .reads = {Resource::LRv},
            .lookUp = {Resource::LRv, Resource::LR}});
    g.markOutput(Resource::Composite);
    g.compile();
    const std::string e = errorOf([&] { g.execute(*ctx_, ""); });
    EXPECT_NE(e.find("pass reader reads LR, which its setup() does not declare"), std::string::npos)
        << e;

    FrameGraph ok;  // declared: runs
    add(ok, {.name = "writer", .writes = {Resource::LRv, Resource::LR}});
    TestPass& reader = add(ok, {.name = "reader",
                                .writes = {Resource::Composite},
                                .reads = {Resource::LRv, Resource::LR},
                                .lookUp = {Resource::LRv, Resource::LR}});
    ok.markOutput(Resource::Composite);
    ok.compile();
    EXPECT_NO_THROW(ok.execute(*ctx_, ""));
    EXPECT_EQ(reader.runs, 1);
}

TEST_F(FrameGraphTest, PublishingAnUndeclaredOrMisdeclaredResourceFails) {
    {
        FrameGraph g;
        add(g, {.name = "sneaky", .writes = {Resource::Composite}, .publishExtra = {Resource::LR}});
        g.markOutput(Resource::Composite);
        g.compile();
        const std::string e = errorOf([&] { g.execute(*ctx_, ""); });
        EXPECT_NE(e.find("sneaky publishes LR, which its setup() does not declare"),
                  std::string::npos)
            << e;
    }
    {
        FrameGraph g;  // declared RGBA16F, publishes RGBA32F
        add(g, {.name = "wrong", .writes = {Resource::Composite}, .publishFormat = GL_RGBA32F});
        g.markOutput(Resource::Composite);
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
        g.importTexture(Resource::CameraImage, GL_SRGB8_ALPHA8, SizeRule::Camera, "camera");
        g.importTexture(Resource::SceneEnvironmentMap, GL_RGBA16F, SizeRule::Scene, "env");
        g.importTexture(Resource::EnvironmentCamera, GL_SRGB8_ALPHA8, SizeRule::Scene, "env cam");
        g.addPass(std::make_unique<EnvironmentPass>());  // the direct pass reads its SH9
        g.addPass(std::make_unique<GBufferPass>());
        auto direct = std::make_unique<DirectLightPass>(*gpu_);
        if (drop)
            g.addPass(std::make_unique<DropRead>(std::move(direct), Resource::GBufferNormal));
        else
            g.addPass(std::move(direct));
        g.addPass(std::make_unique<CompositePass>());
        g.markOutput(Resource::Composite);
        g.markOutput(Resource::CompositeSrgb);
        g.compile();
        g.setImport(Resource::CameraImage, camera_);
        g.setImport(Resource::SceneEnvironmentMap, gpu_->environmentMap());
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
    TestPass& off = add(g, {.name = "off",
                            .writes = {Resource::Vpls},
                            .run = false,
                            .reason = "no light reaches anything"});
    TestPass& dependent =
        add(g, {.name = "dependent", .writes = {Resource::IndirectRv}, .reads = {Resource::Vpls}});
    TestPass& unread = add(g, {.name = "unread", .writes = {Resource::Lenv}});
    TestPass& used = add(g, {.name = "used", .writes = {Resource::DirectRv}});
    TestPass& last = add(g, {.name = "last",
                             .writes = {Resource::Composite},
                             .optionalReads = {Resource::IndirectRv, Resource::DirectRv}});
    g.markOutput(Resource::Composite);
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

// With syncPasses a pass's time is the wall time between a glFinish before and after it: all it
// costs on llvmpipe, also work GL_TIME_ELAPSED does not see (compute dispatches there; here the
// pass sleeps on the CPU, which the GPU timer does not see either: the unsynchronised report
// shows the difference).
TEST_F(FrameGraphTest, SynchronisedPassTimeIsTheWholePass) {
    FrameGraph g;
    add(g, {.name = "slow", .writes = {Resource::Composite}, .cpuMs = 40});
    g.markOutput(Resource::Composite);
    g.compile();
    options_.syncPasses = true;
    const double synced = g.execute(*ctx_, "").passes[0].gpuMs;
    options_.syncPasses = false;
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
