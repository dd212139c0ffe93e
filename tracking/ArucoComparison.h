#pragma once
// mirage's tracker against OpenCV's ArUco detector (DICT_APRILTAG_36h11) + solvePnP on the same
// synthetic frames of the default board (docs/tracking.md, "Benchmark"): the frames, the accuracy
// measures, the ArUco baseline, and one timed comparison for the results page (`mirage bench
// --suite`). The Google Benchmark of tracking/bench/ uses the same frames and measures for its
// finer sweeps.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"
#include "tracking/Board.h"
#include "tracking/Detector.h"

namespace mirage::tracking {

// Rendered views of the default board with their true poses (T_world_camera).
struct BoardFrames {
    CameraIntrinsics camera;
    Board board;
    std::vector<cv::Mat> images;
    std::vector<Pose> truth;
};
// 16 unrelated views: 0.3-0.8 m, 25-88 degrees elevation, several azimuths and rolls. `width`
// 640 (480 high, f = 600 px) or 1280 (720 high, f = 1000 px), mild Brown-Conrady distortion.
BoardFrames singleBoardViews(int width);
// Hard views: `frames` unrelated views far from the board and at a steep angle (drawn from
// `seed`: 0.6-1.1 m from the board centre, 45-70 degrees between the viewing direction and the
// board normal, any azimuth within +-70 degrees, roll +-0.3 rad), each degraded as a webcam's
// frame (motion blur 0-2.5 px, JPEG quality 60-90, exposure 0.6-1.3, sensor noise 0.3-1.2
// levels). Tags of 8-25 px on their shortest side: what a decimated search misses.
BoardFrames hardBoardViews(int width, uint64_t seed, int frames = 16);
// A video: 60 frames at 30 fps of a closed orbit around the board (one turn in 2 s, 180 deg/s,
// 0.45-0.65 m from the board centre, height and aim wobbling): cycling over it is continuous
// motion.
BoardFrames orbitBoardVideo(int width);

// Board tags found in a frame: id and the 4 corners in mirage's order (pixels).
using FoundTags = std::vector<std::pair<int, std::array<glm::dvec2, 4>>>;
FoundTags foundTags(const std::vector<TagDetection>& detections);

// Accuracy over frames: tags found of those visible (4 corners inside, 8 px a side), corner
// error against the projected truth, pose error; a pose off by more than 2 degrees or 2 % of the
// distance is wrong.
struct TrackingAccuracy {
    int visibleTags = 0, foundTags = 0, frames = 0, poses = 0, wrongPoses = 0;
    std::vector<double> cornerErrPx, rotErrDeg, transErrRel;

    void addFrame(const BoardFrames& f, size_t view, const FoundTags& tags,
                  const std::optional<Pose>& pose);
    double detectRate() const;
    double poseRate() const;
    // Medians (-1 when there is nothing to take it of).
    double medianCornerErrPx() const;
    double medianRotErrDeg() const;
    double medianTransErrPercent() const;
};

// OpenCV ArUco per frame: detectMarkers with DICT_APRILTAG_36h11 and the given corner refinement
// (cv::aruco::CORNER_REFINE_*), then solvePnP (iterative) over every board tag's corners.
class ArucoBaseline {
public:
    explicit ArucoBaseline(int cornerRefinement = cv::aruco::CORNER_REFINE_NONE);
    struct Result {
        FoundTags tags;
        std::optional<Pose> pose;  // T_world_camera
    };
    Result process(const BoardFrames& f, const cv::Mat& image);

private:
    cv::Ptr<cv::aruco::Dictionary> dictionary_;
    cv::Ptr<cv::aruco::DetectorParameters> parameters_;
    std::vector<std::vector<cv::Point2f>> corners_;
    std::vector<int> ids_;
};

// One method on one kind of frames.
struct TrackerComparisonRow {
    std::string frames;  // "video" (the orbit, in order) or "single" (unrelated views)
    std::string method;  // "mirage", "ArUco"
    int width = 0, height = 0;
    double medianMs = 0;  // wall time per frame, single-threaded
    TrackingAccuracy accuracy;
};
// mirage's Tracker (default options) and ArUco (no corner refinement: OpenCV's default) on the
// video and on single frames at `width`: each frame timed `repeats` times, OpenCV held to one
// thread as libapriltag runs (restored afterwards). On the video the tracker runs one warm-up
// pass first (it tracks from the previous pose, as in a live session); single frames are 10 s
// apart, so every one is a re-acquisition.
std::vector<TrackerComparisonRow> compareTrackerWithAruco(int width, int repeats);

}  // namespace mirage::tracking
