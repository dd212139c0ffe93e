// `mirage info`: what this build links and whether a GL 4.5 context can be made here.
#include <epoxy/gl.h>

#include "app/Command.h"
#include "core/Log.h"
#include "core/gl/Context.h"

namespace mirage::app {
namespace {
const CommandRegistrar reg("info", [](CLI::App& parent) {
    auto* cmd = parent.add_subcommand("info", "Print the build and the OpenGL context available");
    auto headless = std::make_shared<bool>(true);
    cmd->add_flag("--headless,!--window", *headless, "Headless EGL (default) or a GLFW window");
    cmd->callback([headless] {
        gl::ContextOptions opts;
        auto ctx = *headless ? gl::Context::headless(opts) : gl::Context::window(opts);
        spdlog::info("OpenGL: {} on {}", ctx.versionString(), ctx.rendererName());
    });
});
}  // namespace
}  // namespace mirage::app
