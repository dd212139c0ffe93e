// Voxel number map: precomputation time and LUT size per voxel resolution, and the CPU run-time
// formula for a 32 x 32 image, on the translucent test cube (0.5 m, sigma_t 8 / m; with a
// spherical cavity). Run: build/render/translucency/bench/mirage_vnm_bench
//   --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <filesystem>

#include <benchmark/benchmark.h>

#include "core/image/ImageCompare.h"
#include "render/raytrace/ReferenceRenderer.h"
#include "render/translucency/VoxelNumberMap.h"
#include "testscenes/TranslucentTestScenes.h"

namespace {

using namespace mirage;
using namespace mirage::raytrace::test;

const std::filesystem::path& scratch() {
    static const std::filesystem::path p = [] {
        auto d = std::filesystem::temp_directory_path() / "mirage_vnm_bench";
        std::filesystem::create_directories(d);
        return d;
    }();
    return p;
}

void Precompute(benchmark::State& state) {
    TranslucentSceneOptions o;
    o.shape = state.range(1) ? TranslucentShape::CubeWithCavity : TranslucentShape::Cube;
    const Scene scene = translucentTestScene(o, scratch());
    const auto object = translucency::translucentObjects(scene).at(0);
    translucency::VnmSettings s;
    s.resolution = int(state.range(0));
    s.threads = 2;
    size_t surface = 0, bytes = 0;
    for (auto _ : state) {
        auto map = translucency::VoxelNumberMap::build(object, s);
        surface = map.surface().size();
        bytes = map.lutBytes();
        benchmark::DoNotOptimize(map);
    }
    state.counters["surface_voxels"] = double(surface);
    state.counters["lut_MiB"] = double(bytes) / (1 << 20);
}
BENCHMARK(Precompute)
    ->Args({16, 0})
    ->Args({24, 0})
    ->Args({32, 0})
    ->Args({32, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// 64^3: minutes and a 1 GiB LUT, one iteration (--benchmark_filter=Precompute/64).
BENCHMARK(Precompute)->Args({64, 0})->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void RunTime32x32(benchmark::State& state) {
    TranslucentSceneOptions o;
    const Scene scene = translucentTestScene(o, scratch());
    const auto object = translucency::translucentObjects(scene).at(0);
    translucency::VnmSettings s;
    s.resolution = int(state.range(0));
    s.threads = 2;
    const auto map = translucency::VoxelNumberMap::build(object, s);
    raytrace::EmbreeDevice device("threads=2");
    raytrace::RayTracingScene rt(scene, raytrace::SceneSubset::All, device);
    auto cam = lookAtCamera(32, 32, 70.0, {0.9, 0.55, 1.3}, {0, 0, 0});
    for (auto _ : state) {
        auto img = translucency::renderVnm(map, object, rt, cam.intrinsics, cam.T_world_camera);
        benchmark::DoNotOptimize(img);
    }
}
BENCHMARK(RunTime32x32)->Arg(16)->Arg(32)->Unit(benchmark::kMillisecond)->UseRealTime();

// Time against error per voxel resolution: precomputation + the run-time formula for a 32 x 32
// image of the back-lit cube with a spherical cavity (the accuracy tests' scene), with the PSNR
// over the object against the reference (multiple scattering, 256 spp, rendered once).
void TimeVsError(benchmark::State& state) {
    TranslucentSceneOptions o;
    o.shape = TranslucentShape::CubeWithCavity;
    const Scene scene = translucentTestScene(o, scratch());
    const auto object = translucency::translucentObjects(scene).at(0);
    raytrace::EmbreeDevice device("threads=2");
    raytrace::RayTracingScene rt(scene, raytrace::SceneSubset::All, device);
    auto cam = lookAtCamera(32, 32, 70.0, {0.9, 0.55, 1.3}, {0, 0, 0});
    static const cv::Mat truth = [&] {
        raytrace::RenderSettings st;
        st.samplesPerPixel = 256;
        st.threads = 2;
        st.seed = 5;
        return raytrace::render(rt, cam, st).radiance;
    }();
    translucency::VnmSettings s;
    s.resolution = int(state.range(0));
    s.threads = 2;
    double psnrDb = 0.0;
    for (auto _ : state) {
        auto map = translucency::VoxelNumberMap::build(object, s);
        auto img = translucency::renderVnm(map, object, rt, cam.intrinsics, cam.T_world_camera);
        double peak;
        cv::minMaxLoc(truth.reshape(1), nullptr, &peak);
        psnrDb = psnr(img.radiance, truth, peak, img.mask);
    }
    state.counters["psnr_dB"] = psnrDb;
}
BENCHMARK(TimeVsError)
    ->Arg(8)
    ->Arg(12)
    ->Arg(16)
    ->Arg(24)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
