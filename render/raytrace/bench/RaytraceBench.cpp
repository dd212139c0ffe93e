// Ray throughput of the reference renderer next to plain Embree on the same rays.
//  - coherent: the camera rays of a 640x480 pinhole view (one per pixel centre);
//  - incoherent: random origins inside the scene's bounds with uniformly random directions.
// Single-threaded, so the Mrays/s counters are per core. `RayTracingScene::intersect` adds the
// hit record mirage shades with (position, normals, UVs) on top of rtcIntersect1.
// Also: full path-traced samples per second (1 thread) on the same scene.
#include <benchmark/benchmark.h>

#include "render/raytrace/ReferenceRenderer.h"
#include "render/raytrace/Sampling.h"
#include "testscenes/RaytraceTestScenes.h"

namespace mirage::raytrace {
namespace {

using namespace mirage::raytrace::test;

struct Fixture {
    EmbreeDevice device{"threads=1"};
    Scene scene;
    std::unique_ptr<RayTracingScene> rt;
    std::vector<glm::vec3> coherentO, coherentD, incoherentO, incoherentD;
    RenderCamera camera;

    Fixture() {
        // A tabletop-like scene of ~150k triangles: floor, table, spheres and boxes.
        addObject(scene, "floor", floorPrimitive(8.0f), lambert(glm::vec3(0.6f)), glm::dmat4(1.0));
        addObject(scene, "table", boxPrimitive({-1.0f, 0.7f, -0.6f}, {1.0f, 0.75f, 0.6f}),
                  lambert(glm::vec3(0.5f)), glm::dmat4(1.0));
        Rng rng(1, 2);
        for (int i = 0; i < 12; ++i) {
            glm::dvec3 c(rng.uniform() * 1.6 - 0.8, 0.9, rng.uniform() * 1.0 - 0.5);
            if (i % 2)
                addObject(scene, "ball" + std::to_string(i),
                          spherePrimitive(0.08f + 0.06f * rng.uniform(), 128, 64), glass(1.5f),
                          translate(c));
            else
                addObject(scene, "box" + std::to_string(i),
                          boxPrimitive(glm::vec3(-0.08f), glm::vec3(0.08f)),
                          lambert(glm::vec3(0.7f, 0.3f, 0.2f)), translate(c));
        }
        Light spot;
        spot.type = Light::Type::Spot;
        spot.intensity = 20.0f;
        addLight(scene, "spot", spot,
                 glm::inverse(glm::lookAt(glm::dvec3(0.5, 2.5, 1), glm::dvec3(0, 0.75, 0),
                                          glm::dvec3(0, 1, 0))));
        addCameraNode(scene, "cam", {0, 1.6, 2.0}, {0, 0.8, 0}, 0.8f);
        rt = std::make_unique<RayTracingScene>(scene, SceneSubset::All, device);
        camera = cameraFromNode(scene, "cam", 640, 480);
        const glm::mat3 R(camera.T_world_camera.rotationMatrix());
        for (int y = 0; y < 480; ++y)
            for (int x = 0; x < 640; ++x) {
                coherentO.push_back(glm::vec3(camera.T_world_camera.translation));
                coherentD.push_back(glm::normalize(
                    R * glm::vec3(*camera.intrinsics.unproject({double(x), double(y)}))));
            }
        auto b = rt->sceneBounds();
        for (int i = 0; i < 640 * 480; ++i) {
            glm::vec3 o =
                b.centre + 0.5f * b.radius * (sampleUniformSphere(rng.uniform2()) * rng.uniform());
            incoherentO.push_back(o);
            incoherentD.push_back(sampleUniformSphere(rng.uniform2()));
        }
    }
};

Fixture& fixture() {
    static Fixture f;
    return f;
}

const std::vector<glm::vec3>& origins(bool coherent) {
    return coherent ? fixture().coherentO : fixture().incoherentO;
}
const std::vector<glm::vec3>& directions(bool coherent) {
    return coherent ? fixture().coherentD : fixture().incoherentD;
}

void setRate(benchmark::State& state, size_t raysPerIteration) {
    state.counters["Mrays/s"] = benchmark::Counter(
        double(raysPerIteration) * double(state.iterations()) / 1e6, benchmark::Counter::kIsRate);
}

void BM_EmbreeIntersect1(benchmark::State& state) {
    bool coherent = state.range(0) == 1;
    auto& f = fixture();
    const auto& O = origins(coherent);
    const auto& D = directions(coherent);
    RTCScene scene = f.rt->embreeScene();
    for (auto _ : state) {
        unsigned hits = 0;
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        for (size_t i = 0; i < O.size(); ++i) {
            RTCRayHit rh{};
            rh.ray.org_x = O[i].x, rh.ray.org_y = O[i].y, rh.ray.org_z = O[i].z;
            rh.ray.dir_x = D[i].x, rh.ray.dir_y = D[i].y, rh.ray.dir_z = D[i].z;
            rh.ray.tnear = 1e-4f;
            rh.ray.tfar = std::numeric_limits<float>::infinity();
            rh.ray.mask = 0xFFFFFFFFu;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(scene, &ctx, &rh);
            hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        }
        benchmark::DoNotOptimize(hits);
    }
    setRate(state, O.size());
}

void BM_EmbreeIntersect16(benchmark::State& state) {
    bool coherent = state.range(0) == 1;
    auto& f = fixture();
    const auto& O = origins(coherent);
    const auto& D = directions(coherent);
    RTCScene scene = f.rt->embreeScene();
    alignas(64) int valid[16];
    std::fill(std::begin(valid), std::end(valid), -1);
    for (auto _ : state) {
        unsigned hits = 0;
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        ctx.flags =
            coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
        for (size_t base = 0; base + 16 <= O.size(); base += 16) {
            alignas(64) RTCRayHit16 rh;
            for (int k = 0; k < 16; ++k) {
                const auto& o = O[base + size_t(k)];
                const auto& d = D[base + size_t(k)];
                rh.ray.org_x[k] = o.x, rh.ray.org_y[k] = o.y, rh.ray.org_z[k] = o.z;
                rh.ray.dir_x[k] = d.x, rh.ray.dir_y[k] = d.y, rh.ray.dir_z[k] = d.z;
                rh.ray.tnear[k] = 1e-4f;
                rh.ray.tfar[k] = std::numeric_limits<float>::infinity();
                rh.ray.mask[k] = 0xFFFFFFFFu;
                rh.ray.time[k] = 0.0f;
                rh.ray.flags[k] = 0;
                rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
            }
            rtcIntersect16(valid, scene, &ctx, &rh);
            for (int k = 0; k < 16; ++k) hits += rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
        }
        benchmark::DoNotOptimize(hits);
    }
    setRate(state, O.size() / 16 * 16);
}

void BM_RayTracingSceneIntersect(benchmark::State& state) {
    bool coherent = state.range(0) == 1;
    auto& f = fixture();
    const auto& O = origins(coherent);
    const auto& D = directions(coherent);
    for (auto _ : state) {
        unsigned hits = 0;
        SurfaceHit hit;
        for (size_t i = 0; i < O.size(); ++i)
            hits += f.rt->intersect(O[i], D[i], std::numeric_limits<float>::infinity(), hit);
        benchmark::DoNotOptimize(hits);
    }
    setRate(state, O.size());
}

void BM_RayTracingSceneOccluded(benchmark::State& state) {
    bool coherent = state.range(0) == 1;
    auto& f = fixture();
    const auto& O = origins(coherent);
    const auto& D = directions(coherent);
    for (auto _ : state) {
        unsigned hits = 0;
        for (size_t i = 0; i < O.size(); ++i)
            hits += f.rt->occluded(O[i], D[i], std::numeric_limits<float>::infinity());
        benchmark::DoNotOptimize(hits);
    }
    setRate(state, O.size());
}

// Full reference rendering (path tracing + caustic photons), 160x120, 1 sample, 1 thread.
void BM_RenderOnePass(benchmark::State& state) {
    auto& f = fixture();
    RenderCamera cam = cameraFromNode(f.scene, "cam", 160, 120);
    RenderSettings st;
    st.samplesPerPixel = 1;
    st.threads = 1;
    st.photonsPerPass = 20000;
    st.caustics = state.range(0) == 1;
    for (auto _ : state) benchmark::DoNotOptimize(render(*f.rt, cam, st).passes);
    state.counters["paths/s"] =
        benchmark::Counter(160.0 * 120.0 * double(state.iterations()), benchmark::Counter::kIsRate);
}

BENCHMARK(BM_EmbreeIntersect1)->ArgName("coherent")->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EmbreeIntersect16)->ArgName("coherent")->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RayTracingSceneIntersect)
    ->ArgName("coherent")
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RayTracingSceneOccluded)
    ->ArgName("coherent")
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RenderOnePass)->ArgName("caustics")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace mirage::raytrace

BENCHMARK_MAIN();
