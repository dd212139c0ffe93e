// Tracking benchmark: mirage (libapriltag + refinement + IPPE/LM pose) against OpenCV ArUco with
// DICT_APRILTAG_36h11 + solvePnP, on the same rendered frames of the default board at 640x480 and
// 1280x720. Timings: Google Benchmark (one frame per iteration, cycling over the views).
// Accuracy (detection rate, corner error, pose error, wrong-but-ok poses) is computed once per
// method and resolution and attached to the benchmark as counters.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <memory>

#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "tracking/ArucoComparison.h"
#include "tracking/Detector.h"
#include "tracking/PoseEstimator.h"
#include "tracking/SyntheticTabletop.h"
#include "tracking/Tracker.h"

namespace mirage::tracking {
namespace {

// The frames, built once per width.
const BoardFrames& frames(int width) {
    static std::map<int, std::unique_ptr<BoardFrames>> cache;
    auto& f = cache[width];
    if (!f) f = std::make_unique<BoardFrames>(singleBoardViews(width));
    return *f;
}
const BoardFrames& sequence(int width) {
    static std::map<int, std::unique_ptr<BoardFrames>> cache;
    auto& f = cache[width];
    if (!f) f = std::make_unique<BoardFrames>(orbitBoardVideo(width));
    return *f;
}

// A textured tabletop video (SyntheticTabletop: the board's sheet in 2 m x 2 m of value noise):
// an orbit over the board (30 frames) and a pan of 80 degrees that takes it out of view
// (36 frames, the last ~16 without the board), then the same path backwards, so that cycling
// over it is continuous motion; 30 fps, the camera of the single views.
const BoardFrames& texturedVideo(int width) {
    static std::map<int, std::unique_ptr<BoardFrames>> cache;
    auto& f = cache[width];
    if (f) return *f;
    f = std::make_unique<BoardFrames>();
    f->camera = frames(width).camera;
    const SyntheticTabletop table(frames(width).board);
    f->board = table.board();
    const TexturedPlaneRenderer renderer(f->camera, 2);
    const int orbit = 30, pan = 36;
    std::vector<int> order;
    for (int i = 0; i < orbit + pan; ++i) order.push_back(i);
    for (int i = orbit + pan - 2; i > 0; --i) order.push_back(i);
    for (int i : order) {
        const Pose T = orbitThenPan(i, orbit, pan, 80.0);
        f->images.push_back(table.render(renderer, T));
        f->truth.push_back(T);
    }
    return *f;
}

void report(benchmark::State& state, const TrackingAccuracy& a) {
    state.counters["detect_rate"] = a.detectRate();
    state.counters["corner_err_px_med"] = a.medianCornerErrPx();
    state.counters["rot_err_deg_med"] = a.medianRotErrDeg();
    state.counters["trans_err_pct_med"] = a.medianTransErrPercent();
    state.counters["pose_rate"] = a.poseRate();
    state.counters["wrong_ok"] = a.wrongPoses;
}

std::optional<Pose> okPose(const PoseEstimate& e) {
    return e.state == TrackingState::Ok ? e.pose : std::nullopt;
}

// ---- mirage ----------------------------------------------------------------------------------

struct MirageRun {
    std::vector<TagDetection> detections;
    PoseEstimate estimate;
};

void BM_Mirage(benchmark::State& state) {
    const BoardFrames& f = frames(int(state.range(0)));
    DetectorOptions dopt;
    dopt.decimate = float(state.range(1));
    Detector det(dopt);
    PoseEstimator pe(f.board, f.camera);
    TrackingAccuracy acc;
    for (size_t v = 0; v < f.images.size(); ++v) {
        const auto d = det.detect(f.images[v]);
        acc.addFrame(f, v, foundTags(d), okPose(pe.estimate(d)));
    }
    size_t i = 0;
    for (auto _ : state) {
        const cv::Mat& img = f.images[i++ % f.images.size()];
        auto d = det.detect(img);
        benchmark::DoNotOptimize(pe.estimate(d));
    }
    report(state, acc);
}

// The two stages of BM_Mirage alone: detection (libapriltag + corner refinement), and the pose
// from precomputed detections.
void BM_MirageDetect(benchmark::State& state) {
    const BoardFrames& f = frames(int(state.range(0)));
    DetectorOptions dopt;
    dopt.decimate = float(state.range(1));
    Detector det(dopt);
    size_t i = 0;
    for (auto _ : state) benchmark::DoNotOptimize(det.detect(f.images[i++ % f.images.size()]));
}

void BM_MiragePose(benchmark::State& state) {
    const BoardFrames& f = frames(int(state.range(0)));
    DetectorOptions dopt;
    dopt.decimate = float(state.range(1));
    Detector det(dopt);
    PoseEstimator pe(f.board, f.camera);
    std::vector<std::vector<TagDetection>> dets;
    for (const auto& img : f.images) dets.push_back(det.detect(img));
    size_t i = 0;
    for (auto _ : state) benchmark::DoNotOptimize(pe.estimate(dets[i++ % dets.size()]));
}

BENCHMARK(BM_MirageDetect)
    ->ArgNames({"width", "decimate"})
    ->Args({640, 2})
    ->Args({640, 3})
    ->Args({640, 4})
    ->Args({1280, 2})
    ->Args({1280, 3})
    ->Args({1280, 4})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_MiragePose)
    ->ArgNames({"width", "decimate"})
    ->Args({640, 2})
    ->Args({1280, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// mirage's Tracker over the video (frames in order, cycling). Arg mode: 2 = tracking mode (tags
// found where the predicted pose puts them, verified; default), 1 = libapriltag in the region
// of interest only (the previous default), 0 = libapriltag on the full image every frame; 3 =
// mode 2 with extended tracking's natural features on, as `mirage track` and live run it (on
// this flat-coloured board few features exist: the cost of looking for them).
// Accuracy of the raw per-frame poses over one pass after a first pass to warm up.
void BM_MirageTrack(benchmark::State& state) {
    const BoardFrames& f = sequence(int(state.range(0)));
    TrackerOptions opt;
    opt.roiEnabled = state.range(1) >= 1;
    opt.tagTracking = state.range(1) >= 2;
    // Modes 0 and 1 are libapriltag's search at decimate 2 (the coarse-to-fine search of full
    // frames is measured on single frames, BM_MirageSingle); mode 2 uses it for the periodic full
    // search, as by default.
    opt.coarseToFine = state.range(1) >= 2;
    opt.coarseFirst = state.range(1) >= 2;
    // The board only, as before extended tracking, but in mode 3 (BM_MirageTrackTextured has
    // the features on a textured scene).
    opt.features.enabled = state.range(1) == 3;
    Tracker tracker(f.board, f.camera, opt);
    TrackingAccuracy acc;
    const double dt = 1.0 / 30.0;
    size_t i = 0;
    int retries = 0, tracked = 0, fallbacks = 0;
    double detectMs = 0, poseMs = 0;
    for (; i < f.images.size(); ++i) tracker.process(f.images[i], double(i) * dt);
    for (size_t v = 0; v < f.images.size(); ++v, ++i) {
        const TrackedFrame t = tracker.process(f.images[v], double(i) * dt);
        acc.addFrame(f, v, foundTags(t.detections), okPose(t.estimate));
        retries += t.fullFrameRetry;
        tracked += t.tagTracked;
        detectMs += t.detectMs;
        poseMs += t.poseMs;
        fallbacks += t.tagTrackingTried && !t.tagTracked;
    }
    for (auto _ : state) {
        benchmark::DoNotOptimize(tracker.process(f.images[i % f.images.size()], double(i) * dt));
        ++i;
    }
    report(state, acc);
    state.counters["full_retries"] = retries;
    state.counters["tag_tracked"] = tracked;
    // Wall-clock ms per frame of the two stages over the accuracy pass (one pass, indicative).
    state.counters["detect_ms"] = detectMs / double(f.images.size());
    state.counters["pose_ms"] = poseMs / double(f.images.size());
    state.counters["track_fallbacks"] = fallbacks;
}

BENCHMARK(BM_MirageTrack)
    ->ArgNames({"width", "mode"})
    ->Args({640, 2})
    ->Args({640, 3})
    ->Args({640, 1})
    ->Args({640, 0})
    ->Args({1280, 2})
    ->Args({1280, 3})
    ->Args({1280, 1})
    ->Args({1280, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void runAruco(benchmark::State& state, const BoardFrames& f);

// mirage's Tracker (defaults) over the textured tabletop video that pans away from the board and
// back (texturedVideo), with natural features (features 1, the default) or the board only (0).
// Counters over one pass after a warm-up pass: ok rate (pose_rate), wrong-but-ok poses, frames
// from the features alone, and the features' own cost (tracking, pose, map; wall ms per frame).
// Re-acquisition where there is nothing to find: the textured video's frames with the board out
// of view, each as a single frame (no recent pose; features off, so each frame is searched for
// tags), the defaults (mode 2) or with the window searches off (mode 11: no cascade, no window
// retry). What a lost tracker pays per frame while the camera looks away from the board.
void BM_MirageNoBoard(benchmark::State& state) {
    const BoardFrames& tv = texturedVideo(int(state.range(0)));
    std::vector<const cv::Mat*> away;
    for (size_t v = 0; v < tv.images.size(); ++v)
        if (!boardInView(tv.camera, tv.board, tv.truth[v])) away.push_back(&tv.images[v]);
    TrackerOptions opt;
    opt.filterEnabled = false;
    opt.features.enabled = false;
    if (state.range(1) == 11) opt.windowRetry = opt.coarseFirstCascade = false;
    Tracker tracker(tv.board, tv.camera, opt);
    double t = 0;
    int ok = 0;
    for (const cv::Mat* img : away)
        ok += tracker.process(*img, t += 10.0).estimate.state == TrackingState::Ok;
    size_t i = 0;
    for (auto _ : state)
        benchmark::DoNotOptimize(tracker.process(*away[i++ % away.size()], t += 10.0));
    state.counters["frames"] = double(away.size());
    state.counters["wrong_ok"] = ok;  // no board in view: any ok pose is wrong
}

BENCHMARK(BM_MirageNoBoard)
    ->ArgNames({"width", "mode"})
    ->Args({640, 2})
    ->Args({640, 11})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_MirageTrackTextured(benchmark::State& state) {
    const BoardFrames& f = texturedVideo(int(state.range(0)));
    TrackerOptions opt;
    opt.features.enabled = state.range(1) == 1;
    Tracker tracker(f.board, f.camera, opt);
    TrackingAccuracy acc;
    const double dt = 1.0 / 30.0;
    size_t i = 0;
    int featuresOnly = 0;
    std::vector<double> featureMs;
    for (; i < f.images.size(); ++i) tracker.process(f.images[i], double(i) * dt);
    for (size_t v = 0; v < f.images.size(); ++v, ++i) {
        const TrackedFrame t = tracker.process(f.images[v], double(i) * dt);
        acc.addFrame(f, v, foundTags(t.detections), okPose(t.estimate));
        featuresOnly +=
            t.estimate.state == TrackingState::Ok && t.mode == TrackingMode::FeaturesOnly;
        featureMs.push_back(t.featureMs);
    }
    for (auto _ : state) {
        benchmark::DoNotOptimize(tracker.process(f.images[i % f.images.size()], double(i) * dt));
        ++i;
    }
    report(state, acc);
    std::sort(featureMs.begin(), featureMs.end());
    state.counters["features_only"] = featuresOnly;
    state.counters["feature_ms_med"] = featureMs[featureMs.size() / 2];
}

BENCHMARK(BM_MirageTrackTextured)
    ->ArgNames({"width", "features"})
    ->Args({640, 1})
    ->Args({640, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The natural features' own cost per frame, apart from the tags: FeatureTracker over the
// textured video (grey, 640x480) with the true pose as the board's (1 sigma 0.05 deg, 0.5 mm):
// track (pyramid, KLT forwards and backwards), learn (landmarks refined, new corners detected
// when due), and with estimate 1 also the pose from the landmarks every frame (what a frame
// without the board pays); backward: the pyramid levels of the backward check (1 the default,
// 4 = all, as before); eps_centipx: KLT's stop step in hundredths of a pixel (3 the default, 1
// before); first: the levels of the first forward pass (2 the default, 0 = all at once as before).
// Counters: tracked features and landmark inliers per frame (means).
void BM_FeatureTracking(benchmark::State& state) {
    const BoardFrames& f = texturedVideo(int(state.range(0)));
    std::vector<cv::Mat> grey(f.images.size());
    for (size_t v = 0; v < f.images.size(); ++v) {
        if (f.images[v].channels() == 3)
            cv::cvtColor(f.images[v], grey[v], cv::COLOR_BGR2GRAY);
        else
            grey[v] = f.images[v];
    }
    FeatureTrackingOptions options;
    options.backwardLevels = int(state.range(2));
    options.kltEpsilonPx = 0.01 * double(state.range(3));
    options.kltFirstLevels = int(state.range(4));
    FeatureTracker features(f.board, f.camera, options);
    const double rotVar = std::pow(glm::radians(0.05), 2) / 3, posVar = std::pow(5e-4, 2) / 3;
    auto boardPose = [&](size_t v) {
        PoseEstimate e;
        e.state = TrackingState::Ok;
        e.pose = f.truth[v];
        e.distanceM = glm::length(f.truth[v].translation);
        for (int k = 0; k < 6; ++k) e.covariance[size_t(k * 7)] = k < 3 ? rotVar : posVar;
        return e;
    };
    double tracked = 0, inliers = 0;
    size_t i = 0, n = 0;
    for (auto _ : state) {
        const size_t v = i++ % f.images.size();
        features.track(grey[v], f.truth[v]);
        if (state.range(1) == 1) benchmark::DoNotOptimize(features.estimate(f.truth[v], {}));
        features.learn(grey[v], boardPose(v), true, cv::Rect());
        tracked += features.stats().tracked;
        inliers += features.stats().inliers;
        ++n;
    }
    state.counters["tracked"] = tracked / double(std::max<size_t>(1, n));
    state.counters["inliers"] = inliers / double(std::max<size_t>(1, n));
}

BENCHMARK(BM_FeatureTracking)
    ->ArgNames({"width", "estimate", "backward", "eps_centipx", "first"})
    ->Args({640, 0, 1, 3, 2})
    ->Args({640, 1, 1, 3, 2})
    ->Args({640, 0, 1, 3, 0})
    ->Args({640, 0, 1, 1, 0})
    ->Args({640, 1, 1, 1, 0})
    ->Args({640, 0, 4, 1, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// ArUco per frame over the textured video of BM_MirageTrackTextured.
void BM_ArucoTrackTextured(benchmark::State& state) {
    runAruco(state, texturedVideo(int(state.range(0))));
}

// mirage's Tracker on the single unrelated frames of BM_Mirage (no previous pose: frames 10 s
// apart). Args: mode 2 = coarse-first (the default: the coarse-to-fine search at the decimation
// the textured region's size picks, 4, 3 or none, in a window about the region's centre; then,
// where the decimated search missed tags, the adaptive full-resolution pass), 5 = the default
// with the full-resolution pass off (the default before it), 6-8 = the default with one of
// libapriltag's knobs changed in the full-resolution pass: 6 quad_sigma 0.8, 7 decode_sharpening
// 0.5, 8 refine_edges off; 9 = the default with natural features off (--board-only); 10 = the
// default with libapriltag's edge refinement on in the coarse search (as before mirage's
// refinement took the decimation's error alone); 3 =
// coarse-first as before the window (the whole grown region), 4 = the default with decimation 1 for
// the small tags (libapriltag at full resolution in the window), 1 = coarse-to-fine at the fixed
// `coarse` decimation (libapriltag at that decimation, the other board tags found from that pose at
// full resolution and verified; the previous default from 1000 px width), 0 = libapriltag's search
// at decimate 2 only (= BM_Mirage/decimate:2 inside the Tracker); texture 1 = the search starts in
// the textured region (default), 0 = full image.
void BM_MirageSingle(benchmark::State& state) {
    const BoardFrames& f = frames(int(state.range(0)));
    TrackerOptions opt;
    opt.coarseFirst = state.range(1) >= 2;
    opt.fullResolutionFallback = state.range(1) != 5;
    if (state.range(1) == 6) opt.fullResolutionBlurSigma = 0.8f;
    if (state.range(1) == 7) opt.fullResolutionSharpening = 0.5;
    if (state.range(1) == 8) opt.fullResolutionRefineEdges = false;
    if (state.range(1) == 10) opt.coarseRefineEdges = true;
    if (state.range(1) == 3) opt.coarseWindowFraction = 1.0;
    if (state.range(1) == 4) opt.coarseFirstDecimations = {4.0f, 3.0f, 1.0f};
    opt.features.enabled = state.range(1) != 9;
    opt.coarseToFine = state.range(1) == 1;
    opt.coarseMinWidth = 0;  // mode 1 measured at 640x480 too
    opt.coarseDecimate = float(state.range(2));
    opt.textureRegion = state.range(3) == 1;
    opt.filterEnabled = false;
    Tracker tracker(f.board, f.camera, opt);
    TrackingAccuracy acc;
    double t = 0;
    int coarseUsed = 0, regionUsed = 0, fullResolution = 0;
    for (size_t v = 0; v < f.images.size(); ++v) {
        const TrackedFrame r = tracker.process(f.images[v], t += 10.0);
        acc.addFrame(f, v, foundTags(r.detections), okPose(r.estimate));
        coarseUsed += r.coarseUsed;
        fullResolution += !r.fullResolutionRegion.empty();
        regionUsed += r.textureRegionUsed && !r.fullFrameRetry;
    }
    size_t i = 0;
    for (auto _ : state)
        benchmark::DoNotOptimize(tracker.process(f.images[i++ % f.images.size()], t += 10.0));
    report(state, acc);
    state.counters["coarse_used"] = coarseUsed;
    // Frames whose search stayed inside the textured region (no full-image retry).
    state.counters["region_used"] = regionUsed;
    // Frames with an adaptive full-resolution pass.
    state.counters["full_res_pass"] = fullResolution;
}

// mirage's default Tracker (mode 2 of BM_MirageSingle; mode 10 = libapriltag's edge refinement on
// in the coarse search, as before; mode 11 = the window retry and the coarse-first cascade off,
// the ordinary search of the region where the window finds no tag, as before) and ArUco (no corner
// refinement) on the same single frame, one after the other in each iteration, the order swapped
// every iteration: on a shared machine whose speed drifts by tens of percent within a minute, both
// see the same moments, so their ratio is steadier than that of two separate rows. Counters: each
// one's wall ms per frame, `speedup` = ArUco's time over mirage's (the bar: >= 2), and mirage's
// accuracy over one pass of the 16 views.
void BM_SingleSideBySide(benchmark::State& state) {
    const BoardFrames& f = frames(int(state.range(0)));
    TrackerOptions opt;
    opt.filterEnabled = false;
    if (state.range(1) == 10) opt.coarseRefineEdges = true;
    if (state.range(1) == 11) opt.windowRetry = opt.coarseFirstCascade = false;
    Tracker tracker(f.board, f.camera, opt);
    ArucoBaseline aruco(cv::aruco::CORNER_REFINE_NONE);
    double t = 0, mirageMs = 0, arucoMs = 0;
    TrackingAccuracy acc;
    for (size_t v = 0; v < f.images.size(); ++v) {
        const TrackedFrame r = tracker.process(f.images[v], t += 10.0);
        acc.addFrame(f, v, foundTags(r.detections), okPose(r.estimate));
    }
    // Adds the wall time of run() (ms) to `sum`.
    auto timed = [](double& sum, auto&& run) {
        const auto t0 = std::chrono::steady_clock::now();
        run();
        sum += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                   .count();
    };
    size_t i = 0;
    for (auto _ : state) {
        // Each view twice, once in each order.
        const cv::Mat& image = f.images[(i / 2) % f.images.size()];
        auto runMirage = [&] { benchmark::DoNotOptimize(tracker.process(image, t += 10.0)); };
        auto runAruco = [&] { benchmark::DoNotOptimize(aruco.process(f, image)); };
        if (i++ % 2 == 0) {
            timed(mirageMs, runMirage);
            timed(arucoMs, runAruco);
        } else {
            timed(arucoMs, runAruco);
            timed(mirageMs, runMirage);
        }
    }
    const double n = double(state.iterations());
    state.counters["mirage_ms"] = mirageMs / n;
    state.counters["aruco_ms"] = arucoMs / n;
    state.counters["speedup"] = mirageMs > 0 ? arucoMs / mirageMs : 0.0;
    report(state, acc);
}

BENCHMARK(BM_SingleSideBySide)
    ->ArgNames({"width", "mode"})
    ->Args({640, 2})
    ->Args({640, 10})
    ->Args({640, 11})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Hard footage (hardBoardViews: far, steep, blurred, JPEG; 16 frames at 12 fps per seed, seeds
// 1-3 one after the other), tracked in order by mirage's Tracker (Arg fallback: the adaptive
// full-resolution pass on (default) or off) and per frame by ArUco. Counter `right` = frames of
// the 48 with a pose within 2 deg / 2 % of the distance (mirage: ok poses only), `wrong_ok` =
// the others with a pose. The timing cycles over the 48 frames in order.
const BoardFrames& hardFootage(int width) {
    static std::map<int, std::unique_ptr<BoardFrames>> cache;
    auto& f = cache[width];
    if (!f) {
        f = std::make_unique<BoardFrames>(hardBoardViews(width, 1));
        for (uint64_t seed : {2, 3}) {
            const BoardFrames more = hardBoardViews(width, seed);
            f->images.insert(f->images.end(), more.images.begin(), more.images.end());
            f->truth.insert(f->truth.end(), more.truth.begin(), more.truth.end());
        }
    }
    return *f;
}

void reportHard(benchmark::State& state, const TrackingAccuracy& a) {
    report(state, a);
    state.counters["right"] = a.poses - a.wrongPoses;
}

void BM_MirageHard(benchmark::State& state) {
    const BoardFrames& f = hardFootage(int(state.range(0)));
    TrackerOptions opt;
    opt.fullResolutionFallback = state.range(1) == 1;
    TrackingAccuracy acc;
    const double dt = 1.0 / 12.0;
    // Each seed's pass is its own video: a fresh tracker per 16 frames.
    for (size_t first = 0; first < f.images.size(); first += 16) {
        Tracker tracker(f.board, f.camera, opt);
        for (size_t v = first; v < std::min(first + 16, f.images.size()); ++v) {
            const TrackedFrame r = tracker.process(f.images[v], double(v - first) * dt);
            acc.addFrame(f, v, foundTags(r.detections), okPose(r.estimate));
        }
    }
    Tracker tracker(f.board, f.camera, opt);
    size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(tracker.process(f.images[i % f.images.size()], double(i) * dt));
        ++i;
    }
    reportHard(state, acc);
}

void BM_ArucoHard(benchmark::State& state) {
    const BoardFrames& f = hardFootage(int(state.range(0)));
    ArucoBaseline aruco(int(state.range(1)));
    TrackingAccuracy acc;
    for (size_t v = 0; v < f.images.size(); ++v) {
        const ArucoBaseline::Result r = aruco.process(f, f.images[v]);
        acc.addFrame(f, v, r.tags, r.pose);
    }
    size_t i = 0;
    for (auto _ : state)
        benchmark::DoNotOptimize(aruco.process(f, f.images[i++ % f.images.size()]));
    reportHard(state, acc);
}

BENCHMARK(BM_MirageHard)
    ->ArgNames({"width", "fallback"})
    ->Args({640, 1})
    ->Args({640, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_ArucoHard)
    ->ArgNames({"width", "refine"})
    ->Args({640, cv::aruco::CORNER_REFINE_NONE})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// ---- OpenCV ArUco ----------------------------------------------------------------------------

// ArUco (detectMarkers + solvePnP) per frame over `f`, corner refinement = Arg 1.
void runAruco(benchmark::State& state, const BoardFrames& f) {
    ArucoBaseline aruco(int(state.range(1)));
    TrackingAccuracy acc;
    for (size_t v = 0; v < f.images.size(); ++v) {
        const ArucoBaseline::Result r = aruco.process(f, f.images[v]);
        acc.addFrame(f, v, r.tags, r.pose);
    }
    size_t i = 0;
    for (auto _ : state)
        benchmark::DoNotOptimize(aruco.process(f, f.images[i++ % f.images.size()]));
    report(state, acc);
}

void BM_Aruco(benchmark::State& state) {
    runAruco(state, frames(int(state.range(0))));
}

// ArUco per frame over the same video as BM_MirageTrack.
void BM_ArucoTrack(benchmark::State& state) {
    runAruco(state, sequence(int(state.range(0))));
}

BENCHMARK(BM_ArucoTrackTextured)
    ->ArgNames({"width", "refine"})
    ->Args({640, cv::aruco::CORNER_REFINE_APRILTAG})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK(BM_ArucoTrack)
    ->ArgNames({"width", "refine"})
    ->Args({640, cv::aruco::CORNER_REFINE_NONE})
    ->Args({640, cv::aruco::CORNER_REFINE_APRILTAG})
    ->Args({1280, cv::aruco::CORNER_REFINE_NONE})
    ->Args({1280, cv::aruco::CORNER_REFINE_APRILTAG})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Args: image width, then decimation (mirage) or ArUco's corner refinement method.
BENCHMARK(BM_Mirage)
    ->ArgNames({"width", "decimate"})
    ->Args({640, 2})
    ->Args({640, 3})
    ->Args({640, 4})
    ->Args({640, 1})
    ->Args({1280, 2})
    ->Args({1280, 3})
    ->Args({1280, 4})
    ->Args({1280, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_MirageSingle)
    ->ArgNames({"width", "mode", "coarse", "texture"})
    ->Args({640, 2, 0, 1})
    ->Args({640, 5, 0, 1})
    ->Args({640, 6, 0, 1})
    ->Args({640, 7, 0, 1})
    ->Args({640, 8, 0, 1})
    ->Args({640, 9, 0, 1})
    ->Args({640, 10, 0, 1})
    ->Args({640, 3, 0, 1})
    ->Args({640, 4, 0, 1})
    ->Args({640, 0, 0, 1})
    ->Args({640, 0, 0, 0})
    ->Args({640, 1, 4, 1})
    ->Args({640, 1, 3, 1})
    ->Args({1280, 2, 0, 1})
    ->Args({1280, 5, 0, 1})
    ->Args({1280, 3, 0, 1})
    ->Args({1280, 4, 0, 1})
    ->Args({1280, 1, 4, 1})
    ->Args({1280, 1, 4, 0})
    ->Args({1280, 0, 0, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Aruco)
    ->ArgNames({"width", "refine"})
    ->Args({640, cv::aruco::CORNER_REFINE_NONE})
    ->Args({640, cv::aruco::CORNER_REFINE_SUBPIX})
    ->Args({640, cv::aruco::CORNER_REFINE_APRILTAG})
    ->Args({1280, cv::aruco::CORNER_REFINE_NONE})
    ->Args({1280, cv::aruco::CORNER_REFINE_SUBPIX})
    ->Args({1280, cv::aruco::CORNER_REFINE_APRILTAG})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace mirage::tracking

// Single-threaded comparison: libapriltag runs with threads = 1, so OpenCV (whose ArUco detector
// parallelises internally) is limited to one thread too; CPU time then compares like with like.
int main(int argc, char** argv) {
    cv::setNumThreads(1);
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
