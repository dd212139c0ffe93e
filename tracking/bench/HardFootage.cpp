// Hard footage (docs/tracking.md, "Adaptive detection"): per seed, a pass far from the board at a
// steep angle with motion blur, JPEG and noise (hardBoardViews), tracked in order at 12 fps by
// mirage's Tracker and per frame by OpenCV ArUco (DICT_APRILTAG_36h11 + solvePnP). Prints per
// seed and method the frames tracked right (mirage: ok and within 2 deg / 2 % of the distance;
// ArUco: a pose within those bounds), the wrong-but-ok frames (mirage) or wrong poses (ArUco),
// and the detect rate (board tags found / tags fully in view, >= 8 px a side).
//
//   tracking_hard_footage [--seeds 1,2,3] [--frames 16] [--width 640|1280] [--dump DIR]
// --dump writes the frames as DIR/seed<S>_<frame>.png.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tracking/ArucoComparison.h"
#include "tracking/Tracker.h"

namespace {

using namespace mirage::tracking;

struct Method {
    std::string name;
    std::function<void(TrackerOptions&)> configure;  // empty: ArUco
};

TrackingAccuracy runMirage(const BoardFrames& f, const TrackerOptions& options) {
    Tracker tracker(f.board, f.camera, options);
    TrackingAccuracy acc;
    for (size_t v = 0; v < f.images.size(); ++v) {
        const TrackedFrame r = tracker.process(f.images[v], double(v) / 12.0);
        acc.addFrame(f, v, foundTags(r.detections),
                     r.estimate.state == TrackingState::Ok ? r.estimate.pose : std::nullopt);
    }
    return acc;
}

TrackingAccuracy runAruco(const BoardFrames& f) {
    ArucoBaseline aruco;
    TrackingAccuracy acc;
    for (size_t v = 0; v < f.images.size(); ++v) {
        const ArucoBaseline::Result r = aruco.process(f, f.images[v]);
        acc.addFrame(f, v, r.tags, r.pose);
    }
    return acc;
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<uint64_t> seeds{1, 2, 3};
    int frames = 16, width = 640;
    std::string dump;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--seeds") && i + 1 < argc) {
            seeds.clear();
            std::stringstream ss(argv[++i]);
            for (std::string s; std::getline(ss, s, ',');) seeds.push_back(std::stoull(s));
        } else if (!std::strcmp(argv[i], "--frames") && i + 1 < argc) {
            frames = std::max(1, std::atoi(argv[++i]));
        } else if (!std::strcmp(argv[i], "--dump") && i + 1 < argc) {
            dump = argv[++i];
        } else if (!std::strcmp(argv[i], "--width") && i + 1 < argc) {
            width = std::atoi(argv[++i]);
        } else {
            std::fprintf(
                stderr, "usage: %s [--seeds 1,2,3] [--frames 16] [--width 640|1280] [--dump DIR]\n",
                argv[0]);
            return 2;
        }
    }
    cv::setNumThreads(1);
    const std::vector<Method> methods{
        {"mirage (default)", [](TrackerOptions&) {}},
        {"mirage, coarse search with libapriltag's edge refinement",
         [](TrackerOptions& o) { o.coarseRefineEdges = true; }},
        {"mirage, full-resolution fallback off",
         [](TrackerOptions& o) { o.fullResolutionFallback = false; }},
        {"mirage, decimate 1",
         [](TrackerOptions& o) {
             o.detector.decimate = 1.0f;
             o.fullResolutionFallback = false;
         }},
        {"ArUco NONE", {}},
    };
    std::printf("seed | method | right | wrong | detect rate\n");
    std::vector<int> rightTotal(methods.size(), 0), wrongTotal(methods.size(), 0);
    for (uint64_t seed : seeds) {
        const BoardFrames f = hardBoardViews(width, seed, frames);
        for (size_t v = 0; !dump.empty() && v < f.images.size(); ++v)
            cv::imwrite(dump + "/seed" + std::to_string(seed) + "_" + std::to_string(v) + ".png",
                        f.images[v]);
        for (size_t m = 0; m < methods.size(); ++m) {
            TrackingAccuracy acc;
            if (methods[m].configure) {
                TrackerOptions o;
                methods[m].configure(o);
                acc = runMirage(f, o);
            } else {
                acc = runAruco(f);
            }
            const int right = acc.poses - acc.wrongPoses;
            rightTotal[m] += right;
            wrongTotal[m] += acc.wrongPoses;
            std::printf("%llu | %s | %d/%d | %d | %.3f\n", (unsigned long long)seed,
                        methods[m].name.c_str(), right, acc.frames, acc.wrongPoses,
                        acc.detectRate());
        }
    }
    for (size_t m = 0; m < methods.size(); ++m)
        std::printf("all | %s | %d | %d |\n", methods[m].name.c_str(), rightTotal[m],
                    wrongTotal[m]);
    return 0;
}
