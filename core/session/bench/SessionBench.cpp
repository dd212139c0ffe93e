// How fast sessions are written and read, and how fast camera frames convert: the budget a live
// recording spends per frame. Writes under the system temp folder. Real time (I/O included).
//   ninja -C build mirage_session_bench && build/core/session/bench/mirage_session_bench
#include <benchmark/benchmark.h>
#include <unistd.h>
#include <filesystem>

#include <opencv2/imgproc.hpp>

#include "core/capture/CaptureFormat.h"
#include "core/session/MatroskaScanner.h"
#include "core/session/Session.h"

namespace {

namespace fs = std::filesystem;
using namespace mirage;

// Camera-like content: smooth shading plus texture noise (JPEG does not get it for free).
cv::Mat cameraLikeFrame(int w, int h, int i) {
    cv::Mat img(h, w, CV_8UC3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            img.at<cv::Vec3b>(y, x) = cv::Vec3b(uchar((x + i) * 255 / w), uchar(y * 255 / h), 90);
    cv::Mat noise(h, w, CV_8UC3);
    cv::randn(noise, cv::Scalar::all(0), cv::Scalar::all(6));
    img += noise;
    return img;
}

fs::path freshDir(const std::string& name) {
    const fs::path d =
        fs::temp_directory_path() / ("mirage_bench_" + std::to_string(::getpid())) / name;
    fs::remove_all(d);
    return d;
}

void appendFrames(benchmark::State& state, bool imageSequence) {
    const int w = int(state.range(0)), h = int(state.range(1));
    const cv::Mat frame = cameraLikeFrame(w, h, 0);
    int run = 0;
    for (auto _ : state) {
        state.PauseTiming();
        const fs::path dir = freshDir("append" + std::to_string(run++));
        SessionWriter::Options o;
        o.imageSequence = imageSequence;
        Session meta;
        meta.board = "";
        auto writer = std::make_unique<SessionWriter>(dir, meta, o);
        state.ResumeTiming();
        for (int i = 0; i < 30; ++i) writer->append({frame}, {i / 30.0}, std::nullopt);
        state.PauseTiming();
        writer.reset();
        fs::remove_all(dir);
        state.ResumeTiming();
    }
    state.SetItemsProcessed(state.iterations() * 30);  // items = frames
}

void BM_AppendMkv(benchmark::State& s) {
    appendFrames(s, false);
}
void BM_AppendPng(benchmark::State& s) {
    appendFrames(s, true);
}
BENCHMARK(BM_AppendMkv)
    ->Args({640, 480})
    ->Args({1280, 720})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_AppendPng)
    ->Args({640, 480})
    ->Args({1280, 720})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Reading back through OpenCV/FFmpeg (decode included) and scanning without decoding.
struct RecordedSession {
    fs::path dir;
    explicit RecordedSession(int w, int h) : dir(freshDir("read" + std::to_string(w))) {
        Session meta;
        meta.board = "";
        SessionWriter writer(dir, meta, {});
        for (int i = 0; i < 30; ++i) writer.append({cameraLikeFrame(w, h, i)}, {}, std::nullopt);
    }
    ~RecordedSession() { fs::remove_all(dir); }
};

void BM_ReadMkv(benchmark::State& state) {
    const RecordedSession rec(int(state.range(0)), int(state.range(1)));
    const Session s = readSession(rec.dir);
    for (auto _ : state) {
        auto src = openCameraFrames(s, "main");
        cv::Mat f;
        while (src->read(f)) benchmark::DoNotOptimize(f.data);
    }
    state.SetItemsProcessed(state.iterations() * 30);
}
BENCHMARK(BM_ReadMkv)
    ->Args({640, 480})
    ->Args({1280, 720})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_ScanMatroska(benchmark::State& state) {
    const RecordedSession rec(640, 480);
    for (auto _ : state)
        benchmark::DoNotOptimize(scanMatroska(rec.dir / "main.mkv").completeFrames);
    state.SetItemsProcessed(state.iterations() * 30);
}
BENCHMARK(BM_ScanMatroska)->Unit(benchmark::kMicrosecond)->UseRealTime();

void BM_YuyvToBgr(benchmark::State& state) {
    const int w = int(state.range(0)), h = int(state.range(1));
    const std::vector<uint8_t> yuyv = bgrToYuyv(cameraLikeFrame(w, h, 0));
    const RawFrame f{PixelFormat::Yuyv, w, h, 2 * w, yuyv.data(), yuyv.size(), -1, -1};
    cv::Mat bgr;
    for (auto _ : state) benchmark::DoNotOptimize(convertToBgr(f, bgr));
}
BENCHMARK(BM_YuyvToBgr)->Args({640, 480})->Args({1280, 720})->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
