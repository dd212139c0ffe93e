// Tracking benchmark: mirage (libapriltag + refinement + IPPE/LM pose) against OpenCV ArUco with
// DICT_APRILTAG_36h11 + solvePnP, on the same rendered frames of the default board at 640x480 and
// 1280x720. Timings: Google Benchmark (one frame per iteration, cycling over the views).
// Accuracy (detection rate, corner error, pose error, wrong-but-ok poses) is computed once per
// method and resolution and attached to the benchmark as counters.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>

#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>

#include "testscenes/TrackingViews.h"
#include "tracking/Detector.h"
#include "tracking/PoseEstimator.h"
#include "tracking/Tracker.h"

namespace mirage::tracking {
namespace {

struct Frames {
    CameraIntrinsics cam;
    std::vector<cv::Mat> images;
    std::vector<Pose> truth;
    Board board;
};

const Frames& frames(int width) {
    static std::map<int, std::unique_ptr<Frames>> cache;
    auto& f = cache[width];
    if (f) return *f;
    f = std::make_unique<Frames>();
    const int height = width == 640 ? 480 : 720;
    f->cam = testing::pinholeCamera(width, height, width == 640 ? 600 : 1000);
    f->board = BoardLayout().makeBoard();
    const BoardRaster tex = renderBoard(f->board, 8000, false);
    // 16 views: 0.3-0.8 m, 25-88 degrees elevation, several azimuths and rolls.
    int i = 0;
    for (double dist : {0.3, 0.45, 0.6, 0.8}) {
        for (double elev : {88.0, 60.0, 40.0, 25.0}) {
            const double el = glm::radians(elev), az = glm::radians(-35.0 + 23.0 * (i % 4));
            const glm::dvec3 eye = dist * glm::dvec3(std::cos(el) * std::sin(az), std::sin(el),
                                                     std::cos(el) * std::cos(az));
            const Pose T = testing::lookAt(eye, {0.01 * (i % 3), 0, 0}, {0, 0, -1}, 0.15 * (i % 5));
            f->images.push_back(renderSyntheticBoardView(f->board, tex, f->cam, T));
            f->truth.push_back(T);
            ++i;
        }
    }
    return *f;
}

// A video: 60 frames at 30 fps of a closed orbit around the board (one turn in 2 s, 180 deg/s,
// camera 0.45-0.65 m from the board centre, height and aim wobbling), so that cycling over the
// frames is continuous motion. Used to measure mirage's Tracker with its region of interest
// (the previous pose predicts where the board is) against per-frame ArUco on the same frames.
const Frames& sequence(int width) {
    static std::map<int, std::unique_ptr<Frames>> cache;
    auto& f = cache[width];
    if (f) return *f;
    f = std::make_unique<Frames>();
    const int height = width == 640 ? 480 : 720;
    f->cam = testing::pinholeCamera(width, height, width == 640 ? 600 : 1000);
    f->board = BoardLayout().makeBoard();
    const BoardRaster tex = renderBoard(f->board, 8000, false);
    const int n = 60;
    for (int i = 0; i < n; ++i) {
        const double a = 2 * M_PI * i / n;
        const double r = 0.45 + 0.1 * std::sin(2 * a), h = 0.3 + 0.05 * std::cos(3 * a);
        const glm::dvec3 eye(r * std::sin(a), h, r * std::cos(a));
        const glm::dvec3 target(0.02 * std::sin(3 * a), 0, 0.02 * std::cos(2 * a));
        const Pose T = testing::lookAt(eye, target, {0, 1, 0}, 0.1 * std::sin(a));
        f->images.push_back(renderSyntheticBoardView(f->board, tex, f->cam, T));
        f->truth.push_back(T);
    }
    return *f;
}

struct Accuracy {
    int visibleTags = 0, foundTags = 0, poses = 0, wrongPoses = 0;
    std::vector<double> cornerErr, rotErr, transErr;
};

// Board tags whose 4 corners are inside the image and at least 8 px on a side.
int visibleTags(const Frames& f, size_t view) {
    int n = 0;
    const Pose T_cw = f.truth[view].inverse();
    for (const auto& t : f.board.tags) {
        bool in = true;
        std::array<glm::dvec2, 4> px{};
        auto c = t.cornersInWorld();
        for (int k = 0; k < 4 && in; ++k) {
            auto p = f.cam.project(T_cw * c[size_t(k)]);
            in = p && p->x > 2 && p->y > 2 && p->x < f.cam.width - 3 && p->y < f.cam.height - 3;
            if (p) px[size_t(k)] = *p;
        }
        if (in && glm::length(px[0] - px[1]) >= 8 && glm::length(px[1] - px[2]) >= 8) ++n;
    }
    return n;
}

void addCorners(const Frames& f, size_t view, int id, const std::array<glm::dvec2, 4>& corners,
                Accuracy& a) {
    const BoardTag* t = f.board.find(id);
    if (!t) return;
    const Pose T_cw = f.truth[view].inverse();
    auto c = t->cornersInWorld();
    for (int k = 0; k < 4; ++k) {
        auto p = f.cam.project(T_cw * c[size_t(k)]);
        if (p) a.cornerErr.push_back(glm::length(*p - corners[size_t(k)]));
    }
}

void addPose(const Frames& f, size_t view, const Pose& est, Accuracy& a) {
    const Pose& T = f.truth[view];
    const double rot = glm::degrees(rotationAngleBetween(est.rotation, T.rotation));
    const double trans = glm::length(est.translation - T.translation) / glm::length(T.translation);
    a.rotErr.push_back(rot);
    a.transErr.push_back(trans);
    ++a.poses;
    if (rot > 2.0 || trans > 0.02) ++a.wrongPoses;
}

double median(std::vector<double> v) {
    if (v.empty()) return -1;
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    return v[v.size() / 2];
}

void report(benchmark::State& state, const Accuracy& a, size_t views) {
    state.counters["detect_rate"] = a.visibleTags ? double(a.foundTags) / a.visibleTags : 0;
    state.counters["corner_err_px_med"] = median(a.cornerErr);
    state.counters["rot_err_deg_med"] = median(a.rotErr);
    state.counters["trans_err_pct_med"] = 100 * median(a.transErr);
    state.counters["pose_rate"] = double(a.poses) / double(views);
    state.counters["wrong_ok"] = a.wrongPoses;
}

// One frame of a method's accuracy pass: the board tags it found (id, corners in mirage's order)
// and its pose, if it gave one.
template <typename Tags>
void addFrame(const Frames& f, size_t view, const Tags& tags, const std::optional<Pose>& pose,
              Accuracy& a) {
    a.visibleTags += visibleTags(f, view);
    for (const auto& [id, corners] : tags)
        if (f.board.find(id)) {
            ++a.foundTags;
            addCorners(f, view, id, corners, a);
        }
    if (pose) addPose(f, view, *pose, a);
}

// mirage's detections as (id, corners).
std::vector<std::pair<int, std::array<glm::dvec2, 4>>> tagsOf(const std::vector<TagDetection>& d) {
    std::vector<std::pair<int, std::array<glm::dvec2, 4>>> out;
    for (const auto& t : d) out.emplace_back(t.id, t.corners);
    return out;
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
    const Frames& f = frames(int(state.range(0)));
    DetectorOptions dopt;
    dopt.decimate = float(state.range(1));
    Detector det(dopt);
    PoseEstimator pe(f.board, f.cam);
    Accuracy acc;
    for (size_t v = 0; v < f.images.size(); ++v) {
        const auto d = det.detect(f.images[v]);
        addFrame(f, v, tagsOf(d), okPose(pe.estimate(d)), acc);
    }
    size_t i = 0;
    for (auto _ : state) {
        const cv::Mat& img = f.images[i++ % f.images.size()];
        auto d = det.detect(img);
        benchmark::DoNotOptimize(pe.estimate(d));
    }
    report(state, acc, f.images.size());
}

// The two stages of BM_Mirage alone: detection (libapriltag + corner refinement), and the pose
// from precomputed detections.
void BM_MirageDetect(benchmark::State& state) {
    const Frames& f = frames(int(state.range(0)));
    DetectorOptions dopt;
    dopt.decimate = float(state.range(1));
    Detector det(dopt);
    size_t i = 0;
    for (auto _ : state) benchmark::DoNotOptimize(det.detect(f.images[i++ % f.images.size()]));
}

void BM_MiragePose(benchmark::State& state) {
    const Frames& f = frames(int(state.range(0)));
    DetectorOptions dopt;
    dopt.decimate = float(state.range(1));
    Detector det(dopt);
    PoseEstimator pe(f.board, f.cam);
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
// of interest only (the previous default), 0 = libapriltag on the full image every frame.
// Accuracy of the raw per-frame poses over one pass after a first pass to warm up.
void BM_MirageTrack(benchmark::State& state) {
    const Frames& f = sequence(int(state.range(0)));
    TrackerOptions opt;
    opt.roiEnabled = state.range(1) >= 1;
    opt.tagTracking = state.range(1) >= 2;
    // Modes 0 and 1 are libapriltag's search at decimate 2 (the coarse-to-fine search of full
    // frames is measured on single frames, BM_MirageSingle); mode 2 uses it for the periodic full
    // search, as by default.
    opt.coarseToFine = state.range(1) >= 2;
    Tracker tracker(f.board, f.cam, opt);
    Accuracy acc;
    const double dt = 1.0 / 30.0;
    size_t i = 0;
    int retries = 0, tracked = 0, fallbacks = 0;
    double detectMs = 0, poseMs = 0;
    for (; i < f.images.size(); ++i) tracker.process(f.images[i], double(i) * dt);
    for (size_t v = 0; v < f.images.size(); ++v, ++i) {
        const TrackedFrame t = tracker.process(f.images[v], double(i) * dt);
        addFrame(f, v, tagsOf(t.detections), okPose(t.estimate), acc);
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
    report(state, acc, f.images.size());
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
    ->Args({640, 1})
    ->Args({640, 0})
    ->Args({1280, 2})
    ->Args({1280, 1})
    ->Args({1280, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// mirage's Tracker on the single unrelated frames of BM_Mirage (no previous pose: frames 10 s
// apart). Args: mode 1 = coarse-to-fine (libapriltag at `coarse` decimation, the other board tags
// found from that pose at full resolution and verified; the default with coarse 4 from 1000 px
// width), 0 =
// libapriltag's search at decimate 2 only (= BM_Mirage/decimate:2 inside the Tracker).
void BM_MirageSingle(benchmark::State& state) {
    const Frames& f = frames(int(state.range(0)));
    TrackerOptions opt;
    opt.coarseToFine = state.range(1) == 1;
    opt.coarseMinWidth = 0;  // measured at 640x480 too (off there by default)
    opt.coarseDecimate = float(state.range(2));
    opt.filterEnabled = false;
    Tracker tracker(f.board, f.cam, opt);
    Accuracy acc;
    double t = 0;
    int coarseUsed = 0;
    for (size_t v = 0; v < f.images.size(); ++v) {
        const TrackedFrame r = tracker.process(f.images[v], t += 10.0);
        addFrame(f, v, tagsOf(r.detections), okPose(r.estimate), acc);
        coarseUsed += r.coarseUsed;
    }
    size_t i = 0;
    for (auto _ : state)
        benchmark::DoNotOptimize(tracker.process(f.images[i++ % f.images.size()], t += 10.0));
    report(state, acc, f.images.size());
    state.counters["coarse_used"] = coarseUsed;
}

// ---- OpenCV ArUco ----------------------------------------------------------------------------

struct Aruco {
    cv::Ptr<cv::aruco::Dictionary> dict =
        cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11);
    cv::Ptr<cv::aruco::DetectorParameters> params = cv::aruco::DetectorParameters::create();
};

// OpenCV's DICT_APRILTAG_36h11 decodes the printed tag mirrored relative to libapriltag's corner
// order (measured on rendered boards): mirage corners 0, 1, 2, 3 are ArUco's 1, 0, 3, 2.
std::array<glm::dvec2, 4> toMirageOrder(const std::vector<cv::Point2f>& c) {
    return {glm::dvec2(c[1].x, c[1].y), glm::dvec2(c[0].x, c[0].y), glm::dvec2(c[3].x, c[3].y),
            glm::dvec2(c[2].x, c[2].y)};
}

std::optional<Pose> arucoPose(const Frames& f, const std::vector<int>& ids,
                              const std::vector<std::vector<cv::Point2f>>& corners) {
    std::vector<cv::Point3d> obj;
    std::vector<cv::Point2d> img;
    for (size_t i = 0; i < ids.size(); ++i) {
        const BoardTag* t = f.board.find(ids[i]);
        if (!t) continue;
        auto w = t->cornersInWorld();
        auto c = toMirageOrder(corners[i]);
        for (int k = 0; k < 4; ++k) {
            obj.emplace_back(w[size_t(k)].x, w[size_t(k)].y, w[size_t(k)].z);
            img.emplace_back(c[size_t(k)].x, c[size_t(k)].y);
        }
    }
    if (obj.size() < 4) return std::nullopt;
    cv::Matx33d K(f.cam.fx, 0, f.cam.cx, 0, f.cam.fy, f.cam.cy, 0, 0, 1);
    cv::Mat dist(f.cam.distortion);
    cv::Vec3d rvec, tvec;
    if (!cv::solvePnP(obj, img, K, dist, rvec, tvec, false, cv::SOLVEPNP_ITERATIVE))
        return std::nullopt;
    cv::Matx33d R;
    cv::Rodrigues(rvec, R);
    glm::dmat3 Rg;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) Rg[b][a] = R(a, b);
    return Pose::fromRotationTranslation(Rg, {tvec[0], tvec[1], tvec[2]}).inverse();
}

// ArUco (detectMarkers + solvePnP) per frame over `f`, corner refinement = Arg 1.
void runAruco(benchmark::State& state, const Frames& f) {
    Aruco a;
    a.params->cornerRefinementMethod = int(state.range(1));
    Accuracy acc;
    std::vector<std::vector<cv::Point2f>> corners;
    std::vector<int> ids;
    for (size_t v = 0; v < f.images.size(); ++v) {
        cv::aruco::detectMarkers(f.images[v], a.dict, corners, ids, a.params);
        std::vector<std::pair<int, std::array<glm::dvec2, 4>>> tags;
        for (size_t i = 0; i < ids.size(); ++i)
            tags.emplace_back(ids[i], toMirageOrder(corners[i]));
        addFrame(f, v, tags, arucoPose(f, ids, corners), acc);
    }
    size_t i = 0;
    for (auto _ : state) {
        cv::aruco::detectMarkers(f.images[i++ % f.images.size()], a.dict, corners, ids, a.params);
        benchmark::DoNotOptimize(arucoPose(f, ids, corners));
    }
    report(state, acc, f.images.size());
}

void BM_Aruco(benchmark::State& state) {
    runAruco(state, frames(int(state.range(0))));
}

// ArUco per frame over the same video as BM_MirageTrack.
void BM_ArucoTrack(benchmark::State& state) {
    runAruco(state, sequence(int(state.range(0))));
}

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
    ->ArgNames({"width", "mode", "coarse"})
    ->Args({640, 0, 0})
    ->Args({640, 1, 3})
    ->Args({640, 1, 4})
    ->Args({1280, 0, 0})
    ->Args({1280, 1, 3})
    ->Args({1280, 1, 4})
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
