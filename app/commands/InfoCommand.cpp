// `mirage info`: what this build links and whether a GL 4.5 context can be made here.
// `mirage info --passes SCENE`: the real-time renderer's frame graph for one frame of that scene
// seen from one of its glTF cameras: every pass, what it writes (format, size rule) and reads,
// and whether it ran and why (or why it was skipped or culled). --dot FILE also writes the graph
// for Graphviz (docs/realtime-renderer.md shows how to draw it).
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>

#include <epoxy/gl.h>

#include "app/Command.h"
#include "app/NumberChecks.h"
#include "app/PathChecks.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/gl/Context.h"
#include "core/scene/Scene.h"
#include "render/Renderer.h"
#include "render/raytrace/ReferenceRenderer.h"

namespace mirage::app {
namespace {

struct InfoArgs {
    bool headless = true;
    std::string passesScene, camera, dot;
    int width = 640, height = 480;
    bool noLights = false, markdown = false;
};

void printPasses(const InfoArgs& a) {
    if (a.width < 16 || a.height < 16 || a.width > 8192 || a.height > 8192)
        throw Error("mirage info: --width/--height must be 16..8192 pixels");
    // The DOT file is checked (and its temporary made) before the scene is rendered.
    std::optional<OutputFile> dotOut;
    if (!a.dot.empty())
        dotOut.emplace(a.dot, OutputOrigin::Named,
                       OutputRule{{a.passesScene}, true, "mirage info"});
    Scene scene = loadScene(a.passesScene);
    if (a.noLights) {
        for (Node& n : scene.nodes) n.light = -1;
        scene.lights.clear();
    }
    // The named camera node, or the first one (Scene::findCameraNode lists them when none fits).
    const std::string cameraName = scene.nodes[size_t(scene.findCameraNode(a.camera))].name;
    const raytrace::RenderCamera cam =
        raytrace::cameraFromNode(scene, cameraName, a.width, a.height);
    render::Renderer renderer(scene, cam.intrinsics);
    renderer.render({cam.T_world_camera, cv::Mat(), true});
    std::cout << "frame graph of " << a.passesScene << (a.noLights ? " (lights removed)" : "")
              << ", camera '" << cameraName << "' at " << a.width << "x" << a.height << ":\n"
              << (a.markdown ? renderer.graph().markdown() : renderer.graph().describe());
    if (!a.dot.empty()) {
        std::ofstream out(dotOut->temp());
        out << renderer.graph().dot();
        closeChecked(out, a.dot);
        dotOut->commit();
        spdlog::info("wrote {} (draw it with: dot -Tsvg {} -o graph.svg)", a.dot, a.dot);
    }
}

const CommandRegistrar reg("info", [](CLI::App& parent) {
    auto* cmd = parent.add_subcommand(
        "info", "Print the build and the OpenGL context available, or a scene's frame graph");
    auto a = std::make_shared<InfoArgs>();
    cmd->add_flag("--headless,!--window", a->headless, "Headless EGL (default) or a GLFW window");
    cmd->add_option("--passes", a->passesScene,
                    "Print the real-time renderer's frame graph for one frame of this scene "
                    "(.gltf/.glb): passes, what each reads and writes, why each ran or not");
    cmd->add_option("--camera", a->camera,
                    "With --passes: the scene's camera node to view from (default: the first)");
    cmd->add_option("--width", a->width, "With --passes: image width in pixels (default 640)")
        ->check(wholeIn(16, 8192));
    cmd->add_option("--height", a->height, "With --passes: image height in pixels (default 480)")
        ->check(wholeIn(16, 8192));
    cmd->add_flag("--no-lights", a->noLights,
                  "With --passes: remove the scene's lights first (environment light only)");
    cmd->add_flag("--markdown", a->markdown,
                  "With --passes: print the graph as a markdown table (docs)");
    cmd->add_option("--dot", a->dot, "With --passes: also write the graph as Graphviz DOT here")
        ->check(outputPath(OutputShape::File));
    cmd->callback([a] {
        if (a->passesScene.empty() && (!a->dot.empty() || a->noLights || !a->camera.empty()))
            throw Error("mirage info: --camera, --dot and --no-lights need --passes SCENE");
        gl::ContextOptions opts;
        auto ctx = a->headless ? gl::Context::headless(opts) : gl::Context::window(opts);
        if (!a->passesScene.empty()) {
            printPasses(*a);
            return;
        }
        spdlog::info("OpenGL: {} on {}", ctx.versionString(), ctx.rendererName());
    });
});

}  // namespace
}  // namespace mirage::app
