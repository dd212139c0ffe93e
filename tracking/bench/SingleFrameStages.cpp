// Where a single frame's time goes (docs/tracking.md, "Single frames: coarse-first search"): the
// benchmark's 16 unrelated views, each through a Tracker with no previous pose, `reps` times.
// Per view: the tracker's CPU time per frame (this thread's CPU clock, so that other jobs on
// the machine inflate it less than wall time), the path it took (coarse decimation, coarse pose
// used, textured region), and the CPU time of mirage's own stages on that frame's tags (corner
// refinement of every tag once, the pose estimate). Then libapriltag's own stage timer
// (apriltag_detector_t::tp, wall time) of a decimate-2 search of each view's textured region: the
// ordinary search the coarse-first path replaces. The last column times OpenCV ArUco (no corner
// refinement, one thread) and the tracker again, alternately on the same view, and gives their
// ratio (the speedup; docs/tracking.md, "Single frames against ArUco, paired").
//
//   tracking_single_stages [--width 640|1280] [--reps N] [--view V] [--no-coarse-first]
//                          [--no-full-resolution-fallback] [--coarse-refine-edges]
//                          [--no-window-search]
// --view V measures view V alone (to profile one slow view with perf).
// "coarse d3 none, finer used" = the coarse-first window held no tag at decimation 3 and a finer
// decimation of it gave the pose; "search, window d1" = the decimated search of the region found
// no tag and the window at full resolution was searched before the region (--no-window-search:
// neither). The path says where adaptive detection added tags: "+ full res F/S" = libapriltag at
// full resolution found F of the S missed board tags (S = 0: the whole region searched, no pose to
// predict them), "+ finder N" = the finder found N where the frame's settled pose put them.
#include <apriltag/apriltag.h>
#include <apriltag/common/timeprofile.h>

#include <cstdio>
#include <cstring>
#include <ctime>
#include <map>
#include <string>

#include <opencv2/aruco.hpp>
#include <opencv2/core/utility.hpp>

#include "tracking/ArucoComparison.h"
#include "tracking/TagFamily.h"
#include "tracking/Tracker.h"

namespace {

// This thread's CPU time in milliseconds.
double cpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

// The search path a frame took (the table's "path" column; see the header comment).
std::string pathLabel(const mirage::tracking::TrackedFrame& r) {
    char path[128];
    if (r.windowRetried)
        std::snprintf(path, sizeof path, "search, window d1 %s (%d tags, %d/%d verified)",
                      r.coarseUsed ? "used" : "fell back", r.coarseTags, r.prediction.verified,
                      r.prediction.predicted);
    else if (r.coarseTried)
        std::snprintf(path, sizeof path, "coarse d%.0f%s %s (%d tags, %d/%d verified)",
                      double(r.coarseFirstDecimate), r.coarseCascaded ? " none, finer" : "",
                      r.coarseUsed ? "used" : "fell back", r.coarseTags, r.prediction.verified,
                      r.prediction.predicted);
    else
        std::snprintf(path, sizeof path, "search%s", r.fullFrameRetry ? " + full retry" : "");
    std::string out = path;
    if (!r.fullResolutionRegion.empty())
        out += " + full res " + std::to_string(r.fullResolutionFound) + "/" +
               std::to_string(r.fullResolutionSought);
    if (r.fullResolutionFinderFound > 0)
        out += " + finder " + std::to_string(r.fullResolutionFinderFound);
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace mirage::tracking;
    int width = 640, reps = 20, onlyView = -1;
    bool coarseFirst = true, fullResolutionFallback = true, coarseRefineEdges = false,
         windowSearch = true;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--width") && i + 1 < argc)
            width = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--reps") && i + 1 < argc)
            reps = std::max(1, std::atoi(argv[++i]));
        else if (!std::strcmp(argv[i], "--view") && i + 1 < argc)
            onlyView = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--no-coarse-first"))
            coarseFirst = false;
        else if (!std::strcmp(argv[i], "--no-full-resolution-fallback"))
            fullResolutionFallback = false;
        else if (!std::strcmp(argv[i], "--coarse-refine-edges"))
            coarseRefineEdges = true;
        else if (!std::strcmp(argv[i], "--no-window-search"))
            windowSearch = false;
        else {
            std::fprintf(
                stderr,
                "usage: %s [--width 640|1280] [--reps N] [--view V] [--no-coarse-first] "
                "[--no-full-resolution-fallback] [--coarse-refine-edges] [--no-window-search]\n",
                argv[0]);
            return 2;
        }
    }
    const BoardFrames f = singleBoardViews(width);
    TrackerOptions opt;
    opt.filterEnabled = false;
    opt.coarseFirst = coarseFirst;
    opt.fullResolutionFallback = fullResolutionFallback;
    opt.coarseRefineEdges = coarseRefineEdges;
    opt.windowRetry = opt.coarseFirstCascade = windowSearch;
    Tracker tracker(f.board, f.camera, opt);
    PoseEstimator estimator(f.board, f.camera);
    cv::setNumThreads(1);
    ArucoBaseline aruco(cv::aruco::CORNER_REFINE_NONE);
    const TagFamily family("tag36h11");

    apriltag_detector_t* td = apriltag_detector_create();
    apriltag_family_t* raw = family.raw();
    apriltag_detector_add_family_bits(td, raw, 1);
    td->quad_decimate = 2.0f;
    td->nthreads = 1;
    std::map<std::string, double> stageMs;  // per view, summed over views

    double t = 0, sumFrame = 0, sumRefine = 0, sumPose = 0, sumApril = 0, sumAruco = 0,
           sumMirageAgain = 0;
    std::printf(
        "view | frame ms | path | tags | state | refine ms | pose ms | apriltag d2 ms | tracker "
        "detect / pose / features wall ms | side est px | ArUco / mirage CPU ms, alternating = "
        "speedup\n");
    for (size_t v = 0; v < f.images.size(); ++v) {
        if (onlyView >= 0 && int(v) != onlyView) continue;
        const cv::Mat& grey = f.images[v];
        TrackedFrame r;
        double c0 = cpuMs();
        double detectMs = 0, trackerPoseMs = 0, featureMs = 0;
        for (int i = 0; i < reps; ++i) {
            r = tracker.process(grey, t += 10.0);
            detectMs += r.detectMs / reps;
            trackerPoseMs += r.poseMs / reps;
            featureMs += r.featureMs / reps;
        }
        const double frameMs = (cpuMs() - c0) / reps;

        c0 = cpuMs();
        for (int i = 0; i < reps; ++i)
            for (TagDetection d : r.detections)
                Detector::refineCorners(grey, family.widthAtBorder(), d.corners);
        const double refineMs = (cpuMs() - c0) / reps;
        c0 = cpuMs();
        for (int i = 0; i < reps; ++i) estimator.estimate(r.detections);
        const double poseMs = (cpuMs() - c0) / reps;

        // libapriltag's decimate-2 search of the textured region (grown as the tracker grows it).
        const cv::Rect tex = texturedRegion(grey);
        const int m = int(opt.textureMarginPx);
        const cv::Rect region =
            (tex.area() > 0 ? cv::Rect(tex.x - m, tex.y - m, tex.width + 2 * m, tex.height + 2 * m)
                            : cv::Rect(0, 0, grey.cols, grey.rows)) &
            cv::Rect(0, 0, grey.cols, grey.rows);
        image_u8_t im{region.width, region.height, int(grey.step[0]),
                      const_cast<uint8_t*>(grey.ptr<uint8_t>(region.y)) + region.x};
        c0 = cpuMs();
        for (int i = 0; i < reps; ++i) {
            zarray_t* dets = apriltag_detector_detect(td, &im);
            int64_t last = td->tp->utime;
            for (int k = 0; k < zarray_size(td->tp->stamps); ++k) {
                timeprofile_entry e{};
                zarray_get(td->tp->stamps, k, &e);
                stageMs[e.name] += double(e.utime - last) / 1000.0 / reps;
                last = e.utime;
            }
            apriltag_detections_destroy(dets);
        }
        const double aprilMs = (cpuMs() - c0) / reps;
        // ArUco on the same view, alternating with mirage so that both see the same moments of
        // a machine whose speed drifts.
        double arucoMs = 0, mirageAgainMs = 0;
        for (int i = 0; i < reps; ++i) {
            c0 = cpuMs();
            aruco.process(f, grey);
            arucoMs += (cpuMs() - c0) / reps;
            c0 = cpuMs();
            tracker.process(grey, t += 10.0);
            mirageAgainMs += (cpuMs() - c0) / reps;
        }

        const std::string path = pathLabel(r);
        std::printf(
            "%2zu | %.2f | %s%s | %zu | %s | %.3f | %.3f | %.2f | %.2f / %.2f / %.2f | %.0f | "
            "%.2f / %.2f = %.2f\n",
            v, frameMs, path.c_str(), r.textureRegionUsed ? ", region" : "",
            r.estimate.tagsUsed.size(), trackingStateName(r.estimate.state), refineMs, poseMs,
            aprilMs, detectMs, trackerPoseMs, featureMs, r.coarseFirstSidePx, arucoMs,
            mirageAgainMs, arucoMs / mirageAgainMs);
        sumFrame += frameMs;
        sumAruco += arucoMs;
        sumMirageAgain += mirageAgainMs;
        sumRefine += refineMs;
        sumPose += poseMs;
        sumApril += aprilMs;
    }
    const double n = onlyView >= 0 ? 1.0 : double(f.images.size());
    std::printf("mean | %.2f | | | | %.3f | %.3f | %.2f | | | %.2f / %.2f = %.2f\n", sumFrame / n,
                sumRefine / n, sumPose / n, sumApril / n, sumAruco / n, sumMirageAgain / n,
                sumAruco / sumMirageAgain);
    std::printf("libapriltag stages of the decimate-2 search (wall ms per view, mean):\n");
    for (const auto& [name, ms] : stageMs)
        if (ms / n >= 0.005) std::printf("  %-26s %.3f\n", name.c_str(), ms / n);
    apriltag_detector_destroy(td);
    return 0;
}
