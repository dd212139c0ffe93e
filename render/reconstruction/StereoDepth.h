#pragma once
// Dense depth from pairs of tracked frames (poses known from the tags, so this is two-view
// stereo, not structure from motion): each pair is rectified (cv::stereoRectify, which also undoes
// the Brown-Conrady distortion), matched by semi-global matching (cv::StereoSGBM: its smoothness
// term carries depth across the plain, textureless faces of real objects from their edges, where
// a window correlation finds nothing), and turned into a depth map of the rectified left camera.
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "render/reconstruction/Footage.h"

namespace mirage::reconstruction {

struct StereoOptions {
    // A partner frame's baseline (distance between the camera centres), metres: long enough for
    // depth resolution (1 px of disparity at 0.5 m and 320 px width is about 1.4 cm at 7 cm),
    // short enough that the views still look alike.
    double minBaselineM = 0.035, maxBaselineM = 0.14, preferredBaselineM = 0.07;
    double maxViewAngleDeg = 25.0;  // between the two optical axes
    // Depths kept (metres along the rectified optical axis).
    double minDepthM = 0.15, maxDepthM = 2.0;
    int blockSize = 5;  // SGBM matching window (pixels, odd)
    // SGBM's margin (percent) by which the best disparity's cost must beat the second best:
    // lower keeps more of the plain faces, higher drops more wrong matches.
    int uniquenessRatio = 1;
    int smoothness = 96;  // SGBM's P2 per channel and window pixel (P1 is 8)
    // Partners per frame: each frame is matched with up to this many others, the baselines
    // nearest preferredBaselineM, then the ones nearest 1.5x and 2x it (more depth maps of the
    // same surface from different baselines). One by default: on the tabletop two help at
    // 320x240 and hurt at 640x480 (docs/results.md, "Reconstructed proxies").
    int partnersPerFrame = 1;
    int maxPairs = 24;  // depth maps computed (spread over the frames)
    // A depth is kept when this many other depth maps see the same point (within agreementM
    // plus agreementDepthFraction of the depth, metres); 0 keeps every match.
    int minAgreeingMaps = 2;
    double agreementM = 0.006;
    double agreementDepthFraction = 0.02;
};

// A depth map in a rectified camera: pinhole, no distortion.
struct DepthView {
    int frame = 0, partner = 0;  // session frame numbers of the left and right image
    cv::Mat depth;               // CV_32F metres along the optical axis, 0 = no depth
    cv::Mat bgr;                 // the rectified left image (8-bit BGR, sRGB)
    double fx = 0, fy = 0, cx = 0, cy = 0;
    Pose T_world_camera;  // of the rectified left camera (OpenCV axes)
    double baselineM = 0;
    double validFraction = 0;  // of the pixels
};

// Pairs frames (every pair at most once) and computes their depth maps.
// `progress` is called after each pair (done, total).
std::vector<DepthView> computeDepthViews(const Footage& footage, const StereoOptions& options = {},
                                         const std::function<void(int, int)>& progress = {});

// The pairs computeDepthViews would match (indices into footage.frames), for reports and tests.
std::vector<std::pair<int, int>> chooseStereoPairs(const Footage& footage,
                                                   const StereoOptions& options);

}  // namespace mirage::reconstruction
