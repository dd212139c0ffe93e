// Per-pass GPU time of the real-time renderer (GL_TIME_ELAPSED queries), on a table-top scene:
// a real floor and real box (proxies), a virtual box and a virtual sphere, a real spot light and
// no environment map. Arguments: width, height, VPL count, sphere subdivisions (triangles),
// indirect (VPL gather) resolution divisor, specular objects (0 none, 1 glass sphere, 2 glass
// sphere + mirror box), specularVplStride (1, 4, 16).
// Reported time = the frame's total GPU time (manual time); counters = per-pass ms (mean over the
// iterations; use --benchmark_repetitions and the median aggregate for figures).
// BM_EnvironmentLightSplit: the CPU work of placing the environment's lights per new environment
// frame (render/EnvironmentLights.h), wall time; arguments: fish-eye size, map width, and 1 = a
// camera fixed in the world (the resampling table kept) / 0 = its pose changes every frame (a
// camera mounted on the main camera: the table recomputed).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>

#include "core/gl/Context.h"
#include "core/image/ImageIO.h"
#include "render/EnvironmentLights.h"
#include "render/Renderer.h"
#include "render/passes/direct/DirectLightPass.h"
#include "render/raytrace/DifferentialRendering.h"
#include "render/raytrace/EmbreeDevice.h"
#include "render/raytrace/SyntheticFootage.h"
#include "testscenes/EnvironmentViews.h"
#include "testscenes/SpecularTestScenes.h"
#include "testscenes/TranslucentTestScenes.h"

namespace {

using namespace mirage;

// specular: 0 = the sphere is diffuse blue (the diffuse-only frame), 1 = the sphere is glass
// (IOR 1.5, light absorption), 2 = glass sphere and the virtual box a mirror.
Scene benchScene(int sphereSegments, int specular = 0) {
    Scene s;
    int white = test::addMaterial(s, glm::vec3(0.75f));
    int wood = test::addMaterial(s, {0.55f, 0.35f, 0.2f}, 0.6f);
    int red = test::addMaterial(s, {0.8f, 0.1f, 0.1f});
    int blue = test::addMaterial(s, {0.1f, 0.2f, 0.8f}, 0.3f);
    if (specular >= 1) {
        Material& g = s.materials[size_t(blue)];
        g.baseColor = glm::vec4(1.0f);
        g.metallic = 0.0f;
        g.roughness = 0.0f;
        g.transmission = 1.0f;
        g.ior = 1.5f;
        g.attenuationColor = {0.7f, 0.85f, 1.0f};
        g.attenuationDistance = 0.3f;
    }
    if (specular >= 2) {
        Material& m = s.materials[size_t(red)];
        m.baseColor = glm::vec4(0.95f, 0.95f, 0.95f, 1.0f);
        m.metallic = 1.0f;
        m.roughness = 0.0f;
    }
    test::addFloor(s, "table", 0.0f, 2.0f, wood, Origin::Real);
    test::addBox(s, "real box", {-0.6f, 0.0f, -0.5f}, {-0.3f, 0.3f, -0.2f}, white, Origin::Real);
    test::addBox(s, "virtual box", {0.1f, 0.0f, -0.2f}, {0.35f, 0.25f, 0.05f}, red,
                 Origin::Virtual);
    test::addUvSphere(s, "sphere", {-0.1f, 0.15f, 0.2f}, 0.15f, blue, Origin::Virtual,
                      sphereSegments, 2 * sphereSegments);
    test::addLight(s, Light::Type::Spot, {0.6f, 1.4f, 0.6f},
                   glm::normalize(glm::vec3(-0.6f, -1.4f, -0.6f)), 6.0f, Origin::Real, 0.9f, 0.7f);
    return s;
}

gl::Context& context() {
    static gl::Context ctx = gl::Context::headless();
    return ctx;
}

void BM_Frame(benchmark::State& state) {
    context();
    const int w = int(state.range(0)), h = int(state.range(1));
    render::RendererOptions opt;
    opt.vpl.count = int(state.range(2));
    opt.graph.syncPasses = true;
    opt.indirect.scale =
        int(state.range(4));  // per-pass attribution (see RendererOptions::graph.syncPasses)
    opt.specular.vplStride = int(state.range(6));
    Scene scene = benchScene(int(state.range(3)), int(state.range(5)));
    CameraIntrinsics cam;
    cam.width = w;
    cam.height = h;
    cam.fx = cam.fy = 0.9 * w;
    cam.cx = (w - 1) * 0.5;
    cam.cy = (h - 1) * 0.5;
    render::Renderer r(scene, cam, opt);
    const Pose pose = test::lookAtPose({0.0, 1.0, 1.6}, {0.0, 0.1, 0.0});
    cv::Mat footage(h, w, CV_8UC3, cv::Scalar(90, 110, 130));
    r.render({pose, footage, false});  // warm-up: shader compile, first allocations
    // MIRAGE_BENCH_DUMP=<folder>: also write this configuration's images (sRGB PNG; L_rv, L_r
    // tone-mapped by exposure 1) for a look at what was timed.
    if (const char* dump = std::getenv("MIRAGE_BENCH_DUMP")) {
        const std::filesystem::path d(dump);
        std::filesystem::create_directories(d);
        const std::string tag =
            cv::format("%dx%d_%dvpl_spec%d", w, h, opt.vpl.count, int(state.range(5)));
        writeBgr8(d / ("composite_" + tag + ".png"), r.compositeSrgb());
        writeLinearRgb(d / ("Lrv_" + tag + ".png"), r.readBuffer(render::kLRv));
        writeLinearRgb(d / ("Lr_" + tag + ".png"), r.readBuffer(render::kLR));
    }
    std::map<std::string, double> sums;
    for (auto _ : state) {
        const render::FrameReport& rep = r.render({pose, footage, false});
        for (const auto& p : rep.passes) sums[p.name] += p.gpuMs;
        state.SetIterationTime(rep.totalGpuMs * 1e-3);
    }
    for (const auto& [name, ms] : sums)
        state.counters[name + "_ms"] = benchmark::Counter(ms / double(state.iterations()));
    size_t tris = 0;
    for (const auto& m : scene.meshes)
        for (const auto& p : m.primitives) tris += p.indices.size() / 3;
    state.counters["triangles"] = double(tris);
}

void args(benchmark::internal::Benchmark* b) {
    for (auto [w, h] : {std::pair{640, 480}, std::pair{1024, 768}})
        for (int vpls : {64, 256, 1024}) b->Args({w, h, vpls, 32, 2, 0, 1});
    b->Args({640, 480, 256, 32, 1, 0, 1});   // VPL gather at full resolution
    b->Args({640, 480, 256, 128, 2, 0, 1});  // ~65k more triangles
    b->Args({320, 240, 256, 32, 2, 0, 1});
    // Specular objects: the same frame with the sphere glass, and glass + mirror box;
    // compare with {640, 480, 256, 32, 2, 0} for the extra cost.
    b->Args({640, 480, 256, 32, 2, 1, 1});
    b->Args({640, 480, 256, 32, 2, 2, 1});
    b->Args({640, 480, 256, 32, 2, 1, 4});   // glass, VPLs at the hits interleaved 2x2 (default)
    b->Args({640, 480, 256, 32, 2, 2, 4});   // glass + mirror, default stride
    b->Args({640, 480, 256, 32, 2, 1, 16});  // ... 4x4
}

// Time against error of the specular pipeline end to end: the composite of a virtual
// glass sphere among real things (tests/support/testscenes/SpecularTestScenes.h, the seed's Fig. 2
// example) at 192x144 against the reference renderer's composite (64 spp, caustics off, computed
// once), PSNR/SSIM over the sphere's pixels, for impostor resolution x refinement steps and the
// plain cube-map baseline. Arguments: impostor resolution, refinement steps, baseline (0/1).
// Reported time = frame GPU time; counters: psnr_db, ssim, specgbuf_ms (the tracing pass).
struct SpecularReference {
    test::SpecularScene scene;
    cv::Mat footage, composite, mask;
};

const SpecularReference& specularReference() {
    static const SpecularReference ref = [] {
        SpecularReference r;
        r.scene = test::makeSpecularScene(test::SpecularCase{},
                                          std::filesystem::temp_directory_path() / "mirage_bench");
        r.scene.cam = test::smallCamera(192, 144, 180.0);
        const raytrace::EmbreeDevice device("threads=2");
        raytrace::RenderSettings st;
        st.samplesPerPixel = 64;
        st.seed = 3;
        st.caustics = false;
        const auto d =
            raytrace::renderDifferential(r.scene.scene, device, {r.scene.cam, r.scene.pose}, st);
        r.footage = linearRgbToSrgbBgr8(d.realOnly);
        r.composite =
            linearRgbToSrgbBgr8(raytrace::compositeDifferential(srgbBgr8ToLinearRgb(r.footage), d));
        r.mask = test::sphereMask(r.scene);
        return r;
    }();
    return ref;
}

void BM_SpecularImpostorCurve(benchmark::State& state) {
    context();
    const SpecularReference& ref = specularReference();
    render::RendererOptions opt;
    opt.graph.syncPasses = true;
    opt.temporalBlend = 0.0f;
    opt.impostor.resolution = int(state.range(0));
    opt.impostor.refineSteps = int(state.range(1));
    opt.impostor.cubeMapBaseline = state.range(2) != 0;
    render::Renderer r(ref.scene.scene, ref.scene.cam, opt);
    r.render({ref.scene.pose, ref.footage, true});  // warm-up; builds the impostors
    double specMs = 0;
    for (auto _ : state) {
        const render::FrameReport& rep = r.render({ref.scene.pose, ref.footage, true});
        for (const auto& p : rep.passes)
            if (p.name == "specgbuf") specMs += p.gpuMs;
        state.SetIterationTime(rep.totalGpuMs * 1e-3);
    }
    const cv::Mat out = r.compositeSrgb();
    cv::Mat d;
    cv::absdiff(out, ref.composite, d);
    d.convertTo(d, CV_64FC3);
    cv::multiply(d, d, d);
    const cv::Scalar sum = cv::sum(d.setTo(0, ref.mask == 0));
    const double mse = (sum[0] + sum[1] + sum[2]) / (3.0 * cv::countNonZero(ref.mask));
    state.counters["psnr_db"] = mse > 0 ? 10.0 * std::log10(255.0 * 255.0 / mse) : 99.0;
    state.counters["specgbuf_ms"] = specMs / double(state.iterations());
}

void curveArgs(benchmark::internal::Benchmark* b) {
    for (int res : {64, 128, 256, 512})
        for (int steps : {0, 2, 4, 8}) b->Args({res, steps, 0});
    for (int res : {64, 128, 256, 512}) b->Args({res, 0, 1});
}

// The translucency pass (voxel number map on the GPU, docs/translucency.md) on the back-lit
// translucent cube of the accuracy tests at 320x240, per voxel resolution (argument). Reported
// time = frame GPU time; counters: translucency_ms (both dispatches), direct_ms.
void BM_Translucency(benchmark::State& state) {
    context();
    render::RendererOptions opt;
    opt.graph.syncPasses = true;
    opt.translucency.vnmResolution = int(state.range(0));
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / "mirage_bench_translucency";
    std::filesystem::create_directories(dir);  // the scene's environment map is written there
    const Scene scene =
        raytrace::test::translucentTestScene(raytrace::test::TranslucentSceneOptions{}, dir);
    const auto cam = raytrace::test::lookAtCamera(320, 240, 700.0, {0.9, 0.55, 1.3}, {0, 0, 0});
    render::Renderer r(scene, cam.intrinsics, opt);
    r.render({cam.T_world_camera, cv::Mat(), true});  // warm-up: shader compile, first allocations
    double translucencyMs = 0, directMs = 0;
    for (auto _ : state) {
        const render::FrameReport& rep = r.render({cam.T_world_camera, cv::Mat(), false});
        if (!rep.ran("translucency")) {
            state.SkipWithError("the translucency pass did not run");
            return;
        }
        for (const auto& p : rep.passes) {
            if (p.name == "translucency") translucencyMs += p.gpuMs;
            if (p.name == "direct") directMs += p.gpuMs;
        }
        state.SetIterationTime(rep.totalGpuMs * 1e-3);
    }
    state.counters["translucency_ms"] = translucencyMs / double(state.iterations());
    state.counters["direct_ms"] = directMs / double(state.iterations());
}
}  // namespace

BENCHMARK(BM_SpecularImpostorCurve)
    ->Apply(curveArgs)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);
BENCHMARK(BM_Translucency)
    ->Arg(8)
    ->Arg(16)
    ->Arg(24)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
// A sun (8 degrees radius, 40 degrees up, radiance 8) over a sky, filmed by an upward equidistant
// fish-eye (190 degrees) at exposure 0.1.
void BM_EnvironmentLightSplit(benchmark::State& state) {
    const int size = int(state.range(0)), width = int(state.range(1));
    const bool fixedPose = state.range(2) != 0;
    const CameraIntrinsics K = raytrace::equidistantFisheye(size, 190.0);
    const Pose up = Pose::fromRotationTranslation(glm::dmat3(1, 0, 0, 0, 0, -1, 0, 1, 0),
                                                  glm::dvec3(0.0, 0.02, -0.4));
    const glm::dvec3 sun = glm::normalize(glm::dvec3(-0.66, 0.64, -0.38));
    const cv::Mat frame = test::renderEnvironmentView(K, up, [&](const glm::dvec3& d) {
        if (glm::dot(d, sun) > std::cos(glm::radians(8.0))) return glm::vec3(0.8f);
        return glm::vec3(float(0.01 + 0.01 * std::max(d.y, 0.0)));
    });
    render::EnvironmentLightFinder finder;
    int lights = 0;
    double turn = 0;
    for (auto _ : state) {
        Pose T = up;
        if (!fixedPose) {
            turn += 1e-3;  // a new pose every frame
            T.rotation = glm::angleAxis(turn, glm::dvec3(0, 1, 0)) * up.rotation;
        }
        const render::EnvironmentLightSplit split =
            finder.find(frame, K, -1.0, T, glm::vec3(10.0f), width);
        lights = int(split.lights.size());
        benchmark::DoNotOptimize(split.lightFreeSH);
    }
    state.counters["lights"] = lights;
}
BENCHMARK(BM_EnvironmentLightSplit)
    ->Args({480, 128, 1})
    ->Args({480, 256, 1})
    ->Args({480, 512, 1})
    ->Args({480, 256, 0})
    ->Args({960, 256, 1})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
BENCHMARK(BM_Frame)->Apply(args)->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK_MAIN();
