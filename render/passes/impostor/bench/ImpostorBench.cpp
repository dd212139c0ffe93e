// Time vs error of traceSurroundings(): reflected-scene impostors over impostor resolution and
// refinement steps, against the plain G-buffer cube-map baseline, on the impostor test scene
// (tests/support/testscenes/ImpostorTestScene.h, with the enclosing room). Each configuration
// traces the same rays from both specular objects' surfaces (uniform over the outer hemisphere) and
// compares with exact Embree ray casts (computed once). Arguments: impostor resolution, refinement
// steps, baseline (1 = cube map), near object (0 = the red box, 1 = a finely tessellated red
// sphere: curved, where refinement matters). Reported time = GPU time of tracing kRays rays in one
// compute dispatch (GL_TIME_ELAPSED, manual time); counters: hit/miss agreement, origin agreement,
// median / p90 / mean hit-position error (mm), the one-off build time (ms, wall clock) and texture
// memory (MiB). Run: build/render/passes/impostor/bench/mirage_impostor_bench
// --benchmark_repetitions=3
//      --benchmark_report_aggregates_only=true   (docs/impostors.md)
#include <benchmark/benchmark.h>

#include <memory>

#include "core/gl/Context.h"
#include "render/GpuScene.h"
#include "render/passes/impostor/ImpostorAccuracy.h"
#include "render/passes/impostor/ImpostorPass.h"
#include "render/raytrace/EmbreeDevice.h"
#include "render/raytrace/RayTracingScene.h"
#include "testscenes/ImpostorTestScene.h"

namespace {

using namespace mirage;

constexpr int kRaysPerObject = 16384;  // 32768 rays in all (2 specular objects)

gl::Context& context() {
    static gl::Context ctx = gl::Context::headless();
    return ctx;
}

struct Fixture {
    Scene scene;
    std::unique_ptr<render::GpuScene> gpu;
    std::vector<render::ImpostorRay> rays;
    std::vector<render::ExactHit> exact;
    explicit Fixture(bool nearSphere) : scene(test::impostorTestScene(true, 32, nearSphere)) {
        context();
        gpu = std::make_unique<render::GpuScene>(scene, 64);
        raytrace::EmbreeDevice device;
        raytrace::RayTracingScene rt(scene, raytrace::SceneSubset::All, device);
        rays = render::sampleSpecularSurfaceRays(scene, *gpu, kRaysPerObject, 2024);
        exact = render::castExact(rays, *gpu, rt);
    }
};

Fixture& fixture(bool nearSphere) {
    static Fixture box(false);
    static Fixture sphere(true);
    return nearSphere ? sphere : box;
}

void BM_Trace(benchmark::State& state) {
    Fixture& f = fixture(state.range(3) != 0);
    render::RendererOptions o;
    o.impostor.resolution = int(state.range(0));
    o.impostor.refineSteps = int(state.range(1));
    o.impostor.cubeMapBaseline = state.range(2) != 0;
    render::ImpostorPass pass;
    pass.update(*f.gpu, o);
    double ms = 0.0;
    const std::vector<render::ImpostorHit> hits = pass.trace(f.rays, ms);
    const render::ImpostorAccuracy a = render::compareHits(hits, f.exact);
    // The same over the rays whose exact hit is a billboard item (boxes, spheres): where the
    // method matters; planes are exact and dominate the overall median.
    std::vector<render::ImpostorHit> objHits;
    std::vector<render::ExactHit> objExact;
    for (size_t i = 0; i < f.rays.size(); ++i)
        if (f.exact[i].hit && pass.itemKind(f.rays[i].specularSlot, f.exact[i].draw) ==
                                  render::ImpostorPass::ItemKind::Billboard) {
            objHits.push_back(hits[i]);
            objExact.push_back(f.exact[i]);
        }
    const render::ImpostorAccuracy b = render::compareHits(objHits, objExact);
    for (auto _ : state) {
        pass.trace(f.rays, ms);
        state.SetIterationTime(ms * 1e-3);
    }
    state.counters["rays"] = double(f.rays.size());
    state.counters["agree"] = a.hitMissAgreement;
    state.counters["origin"] = a.originAgreement;
    state.counters["med_mm"] = a.medianErrorMm;
    state.counters["p90_mm"] = a.p90ErrorMm;
    state.counters["mean_mm"] = a.meanErrorMm;
    state.counters["obj_rays"] = double(b.rays);
    state.counters["obj_agree"] = b.hitMissAgreement;
    state.counters["obj_med_mm"] = b.medianErrorMm;
    state.counters["obj_p90_mm"] = b.p90ErrorMm;
    state.counters["build_ms"] = pass.buildStats().wallMs;
    state.counters["MiB"] = double(pass.buildStats().textureBytes) / (1024.0 * 1024.0);
}

void args(benchmark::internal::Benchmark* b) {
    for (int nearSphere : {0, 1})
        for (int res : {64, 128, 256, 512}) {
            b->Args({res, 0, 1, nearSphere});  // cube-map baseline (steps do not apply)
            for (int steps : {0, 1, 2, 4, 8}) b->Args({res, steps, 0, nearSphere});
        }
}

}  // namespace

BENCHMARK(BM_Trace)
    ->Apply(args)
    ->ArgNames({"res", "steps", "cube", "curved"})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);
BENCHMARK_MAIN();
