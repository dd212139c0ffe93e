// The headless GL path: an EGL surfaceless 4.5 core context renders into a framebuffer and the
// pixels read back are the ones drawn.
#include <gtest/gtest.h>

#include "core/Error.h"
#include "core/gl/Context.h"
#include "core/gl/Objects.h"

namespace mirage::gl {
namespace {

constexpr const char* kVert = R"(#version 450 core
// Full-screen triangle from gl_VertexID; no vertex buffer needed.
out vec2 uv;
void main() {
    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    uv = p;
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
})";

constexpr const char* kFrag = R"(#version 450 core
in vec2 uv;
uniform vec3 tint;
layout(location = 0) out vec4 color;
// Left half red-ish, right half tinted: a pattern we can check pixel by pixel.
void main() { color = uv.x < 0.5 ? vec4(1.0, 0.25, 0.0, 1.0) : vec4(tint, 1.0); })";

TEST(GlContext, HeadlessRendersAndReadsBack) {
    Context ctx = Context::headless();
    EXPECT_EQ(ctx.kind(), Context::Kind::Headless);
    EXPECT_FALSE(ctx.rendererName().empty());

    const int w = 64, h = 32;
    Texture color = Texture::create2D("test color", w, h, GL_RGBA32F);
    Framebuffer fb("test fb");
    fb.attachColor(0, color);
    fb.finalize(1);
    Program prog("test program", {{GL_VERTEX_SHADER, "test.vert", kVert},
                                  {GL_FRAGMENT_SHADER, "test.frag", kFrag}});
    VertexArray vao("empty vao");
    TimerQuery timer("draw timer");

    fb.bind();
    glViewport(0, 0, w, h);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);
    prog.use();
    glUniform3f(prog.uniformLocation("tint"), 0.0f, 0.5f, 1.0f);
    vao.bind();
    timer.begin();
    glDrawArrays(GL_TRIANGLES, 0, 3);
    timer.end();
    EXPECT_GE(timer.elapsedMs(), 0.0);
    ASSERT_EQ(glGetError(), GLenum(GL_NO_ERROR));

    auto px = color.read<float>(GL_RGBA, GL_FLOAT, 4);
    auto at = [&](int x, int y, int c) { return px[(size_t(y) * w + x) * 4 + c]; };
    EXPECT_FLOAT_EQ(at(5, 5, 0), 1.0f);
    EXPECT_FLOAT_EQ(at(5, 5, 1), 0.25f);
    EXPECT_FLOAT_EQ(at(60, 20, 1), 0.5f);
    EXPECT_FLOAT_EQ(at(60, 20, 2), 1.0f);
}

TEST(GlContext, BadShaderGivesErrorNamingIt) {
    Context ctx = Context::headless();
    try {
        Program p("broken", {{GL_FRAGMENT_SHADER, "broken.frag",
                              "#version 450 core\nvoid main() { x = 1; }"}});
        FAIL() << "expected a compile error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("broken.frag"), std::string::npos) << e.what();
    }
}

TEST(GlContext, TwoContextsInOneProcess) {
    Context a = Context::headless();
    Context b = Context::headless();
    a.makeCurrent();
    Texture t = Texture::create2D("a tex", 4, 4, GL_RGBA8);
    EXPECT_NE(t.id(), 0u);
}

}  // namespace
}  // namespace mirage::gl
