// The Tracker's coarse-first search of frames without a recent pose (TrackerOptions::
// coarseFirst): the textured region's size estimates the tags' size, which picks the decimation
// of the coarse-to-fine search (4, 3, or none: the ordinary search; 1 = full resolution when
// listed), read in a window about the region's centre (coarseWindowFraction). Whatever it picks, a
// frame whose coarse pose is not confirmed falls back to the ordinary search.
#include <gtest/gtest.h>

#include <cstdio>
#include <functional>

#include <opencv2/imgproc.hpp>

#include "testscenes/TrackingViews.h"
#include "tracking/Tracker.h"

namespace mirage::tracking {
namespace {

using Scene = testing::BoardViewScene;
const Scene& scene() {
    return testing::boardViewScene();
}

using testing::orbit;

// One unrelated frame through a fresh Tracker (no previous pose): the defaults (coarse-first
// on), or with the coarse-first search off (libapriltag's ordinary search in the textured region).
TrackedFrame single(const cv::Mat& img, bool coarseFirst, const Board* board = nullptr,
                    double minSidePx = TrackerOptions{}.coarseFirstMinSidePx,
                    double windowFraction = TrackerOptions{}.coarseWindowFraction,
                    bool fullResolution = false, bool cascade = true) {
    TrackerOptions o;
    o.coarseFirstCascade = cascade;
    if (fullResolution) o.coarseFirstDecimations.push_back(1.0f);
    o.coarseFirst = coarseFirst;
    o.coarseFirstMinSidePx = minSidePx;
    o.coarseWindowFraction = windowFraction;
    o.filterEnabled = false;
    Tracker tracker(board ? *board : scene().board, scene().cam, o);
    return tracker.process(img, 0.0);
}

double rotationDeg(const Pose& a, const Pose& b) {
    return glm::degrees(rotationAngleBetween(a.rotation, b.rotation));
}

// Near, middle and far views: the decimation follows the tags' size, and the pose is the
// ordinary search's.
TEST(CoarseFirst, DecimationFollowsTheTagSize) {
    struct View {
        const char* name;
        Pose T;
        float decimate;  // expected choice
    };
    const std::vector<View> views = {
        {"0.3 m", testing::lookAt(orbit(0.3, 75, 10), {0, 0, 0}), 4.0f},
        {"0.5 m", testing::lookAt(orbit(0.5, 60, -20), {0.01, 0, 0}), 3.0f},
        {"0.8 m", testing::lookAt(orbit(0.8, 50, 15), {0, 0, 0}), 0.0f},
    };
    for (const View& v : views) {
        const cv::Mat img = scene().render(v.T);
        const TrackedFrame c = single(img, true), o = single(img, false);
        std::printf("%s: estimated side %.1f px, decimate %.0f, coarse used %d, %zu vs %zu tags\n",
                    v.name, c.coarseFirstSidePx, double(c.coarseFirstDecimate), int(c.coarseUsed),
                    c.estimate.tagsUsed.size(), o.estimate.tagsUsed.size());
        EXPECT_EQ(c.coarseFirstDecimate, v.decimate) << v.name;
        EXPECT_EQ(c.coarseTried, v.decimate > 0) << v.name;
        ASSERT_EQ(c.estimate.state, TrackingState::Ok) << v.name << ": " << c.estimate.reason;
        ASSERT_EQ(o.estimate.state, TrackingState::Ok) << v.name << ": " << o.estimate.reason;
        if (v.decimate > 0) {
            EXPECT_TRUE(c.coarseUsed) << v.name;
            EXPECT_GE(c.estimate.tagsUsed.size(), o.estimate.tagsUsed.size()) << v.name;
        }
        // With the same tags the ordinary search's pose; with more (the far view: the finder
        // adds the small tags libapriltag's search misses) closer to the truth.
        if (c.estimate.tagsUsed.size() == o.estimate.tagsUsed.size()) {
            EXPECT_LT(rotationDeg(*c.estimate.pose, *o.estimate.pose), 0.02) << v.name;
            EXPECT_LT(glm::length(c.estimate.pose->translation - o.estimate.pose->translation),
                      2e-4)
                << v.name;
        } else {
            EXPECT_LE(rotationDeg(*c.estimate.pose, v.T), rotationDeg(*o.estimate.pose, v.T))
                << v.name;
        }
        EXPECT_LT(rotationDeg(*c.estimate.pose, v.T), 0.1) << v.name;
    }
}

// The hard views (as in HardCases and TexturedRegion): the coarse-first search gives the state
// of the ordinary search, or ok from more tags; where ok, the ordinary search's pose (within
// 0.05 deg / 0.3 mm; with the same tags) and within 0.5 deg / 1 % of the truth. A coarse pose that
// is not confirmed never becomes the frame's.
TEST(CoarseFirst, SameStateAsTheOrdinarySearchOnHardViews) {
    struct View {
        const char* name;
        Pose T;
        std::function<void(cv::Mat&)> modify;
    };
    const std::vector<View> views = {
        {"steep 70 deg", testing::lookAt(orbit(0.45, 20, 10), {0, 0, 0}, {0, 1, 0}), {}},
        {"steep 78 deg", testing::lookAt(orbit(0.35, 12, 0), {0, 0, 0}, {0, 1, 0}), {}},
        {"motion blur 9 px", testing::lookAt(orbit(0.45, 60, 15), {0, 0, 0}),
         [](cv::Mat& img) {
             cv::Mat k = cv::Mat::zeros(1, 9, CV_32F) + 1.0f / 9;
             cv::filter2D(img, img, -1, k);
         }},
        {"occluded half", testing::lookAt(orbit(0.4, 65, -10), {0, 0, 0}),
         [](cv::Mat& img) {
             cv::rectangle(img, {0, 0}, {img.cols / 2, img.rows}, cv::Scalar(60), cv::FILLED);
         }},
        {"exposure x0.2", testing::lookAt(orbit(0.4, 60, 5), {0, 0, 0}),
         [](cv::Mat& img) { img.convertTo(img, -1, 0.2, 0); }},
        {"board cut by the image edge", testing::lookAt(orbit(0.35, 70, 0), {0.12, 0, 0.05}), {}},
        {"distant 1.1 m", testing::lookAt(orbit(1.1, 80, 0), {0, 0, 0}), {}},
    };
    int coarseUsed = 0;
    for (const View& v : views) {
        cv::Mat img = scene().render(v.T);
        if (v.modify) v.modify(img);
        const TrackedFrame c = single(img, true), o = single(img, false);
        std::printf("%s: %s (decimate %.0f, coarse tags %d, used %d), ordinary search %s\n", v.name,
                    trackingStateName(c.estimate.state), double(c.coarseFirstDecimate),
                    c.coarseTags, int(c.coarseUsed), trackingStateName(o.estimate.state));
        coarseUsed += c.coarseUsed;
        // The ordinary search's state, or ok from more tags (the distant view: the finder adds
        // the small tags the ordinary search misses) and then right (below).
        const bool moreTags = c.coarseUsed && c.estimate.state == TrackingState::Ok &&
                              c.estimate.tagsUsed.size() > o.estimate.tagsUsed.size();
        if (!moreTags) {
            ASSERT_EQ(c.estimate.state, o.estimate.state) << v.name << ": " << c.estimate.reason;
        }
        ASSERT_EQ(c.estimate.pose.has_value(), o.estimate.pose.has_value()) << v.name;
        if (c.estimate.state != TrackingState::Ok) continue;
        if (!moreTags) {
            EXPECT_LT(rotationDeg(*c.estimate.pose, *o.estimate.pose), 0.05) << v.name;
            EXPECT_LT(glm::length(c.estimate.pose->translation - o.estimate.pose->translation),
                      3e-4)
                << v.name;
        }
        EXPECT_LT(rotationDeg(*c.estimate.pose, v.T), 0.5) << v.name;
        EXPECT_LT(glm::length(c.estimate.pose->translation - v.T.translation),
                  0.01 * glm::length(v.T.translation))
            << v.name;
    }
    // At least one of these views takes the coarse path (the board cut by the image edge), not
    // only the fallback.
    EXPECT_GE(coarseUsed, 1);
}

// Must fail: the coarse path forced on a view whose tags are too small for it (every decimation
// allowed whatever the estimated size; no cascade to finer decimations, WindowRetry_test.cpp)
// finds nothing usable and falls back: the frame gets exactly the ordinary search's pose. And a
// wrong board file (wrong gap: the tags do not fit one pose; every tag turned by 90 degrees) gives
// no ok pose through the coarse path, while the right board on the same frame does (the comparison
// can pass).
TEST(CoarseFirst, ForcedOnSmallTagsFallsBackAndAWrongBoardGivesNoPose) {
    const cv::Mat far = scene().render(testing::lookAt(orbit(0.8, 45, -10), {0, 0, 0}));
    const TrackedFrame forced = single(far, true, nullptr, 0.0,
                                       TrackerOptions{}.coarseWindowFraction, false, false),
                       o = single(far, false);
    std::printf("forced: decimate %.0f, coarse tags %d, used %d; %s\n",
                double(forced.coarseFirstDecimate), forced.coarseTags, int(forced.coarseUsed),
                trackingStateName(forced.estimate.state));
    EXPECT_EQ(forced.coarseFirstDecimate, 4.0f);
    EXPECT_TRUE(forced.coarseTried);
    EXPECT_FALSE(forced.coarseUsed);
    ASSERT_EQ(forced.estimate.state, o.estimate.state) << forced.estimate.reason;
    ASSERT_TRUE(forced.estimate.pose && o.estimate.pose);
    EXPECT_EQ(forced.estimate.tagsUsed, o.estimate.tagsUsed);
    // The same tags and pose (adaptive detection's finder adds the same tags in both; the
    // estimates then differ in the last digits: 2e-6 deg measured).
    EXPECT_LT(rotationDeg(*forced.estimate.pose, *o.estimate.pose), 1e-4);

    const cv::Mat near = scene().render(testing::lookAt(orbit(0.35, 70, 10), {0, 0, 0}));
    BoardLayout wrongGap;
    wrongGap.gap = 0.012;
    Board turned = scene().board;
    const Pose turn = Pose::fromRotationTranslation(glm::dmat3(0, 1, 0, -1, 0, 0, 0, 0, 1), {});
    for (auto& t : turned.tags) t.T_world_tag = t.T_world_tag * turn;
    for (const Board& board : {wrongGap.makeBoard(), turned}) {
        const TrackedFrame c = single(near, true, &board);
        std::printf("wrong board: %s (%s), decimate %.0f, coarse tags %d\n",
                    trackingStateName(c.estimate.state), c.estimate.reason.c_str(),
                    double(c.coarseFirstDecimate), c.coarseTags);
        EXPECT_TRUE(c.coarseTried);
        EXPECT_GT(c.coarseTags, 0);
        EXPECT_FALSE(c.coarseUsed);
        EXPECT_NE(c.estimate.state, TrackingState::Ok) << c.estimate.reason;
    }
    const TrackedFrame right = single(near, true);
    EXPECT_EQ(right.estimate.state, TrackingState::Ok) << right.estimate.reason;
    EXPECT_TRUE(right.coarseUsed);
}

// The coarse window (coarseWindowFraction): libapriltag reads only a window about the textured
// region's centre, finds fewer tags there than in the whole region, and the finder the others:
// the same tags and pose as with the whole region, near (decimation 4) and far (full resolution,
// decimation 1 listed).
// Must fail: with the board's centre covered the window holds no tag: no coarse tag, and the
// frame falls back to exactly the ordinary search's state, tags and pose.
TEST(CoarseFirst, WindowFindsAFewTagsAndTheFinderTheOthers) {
    const std::vector<std::pair<const char*, Pose>> views = {
        {"0.35 m", testing::lookAt(orbit(0.35, 70, 10), {0, 0, 0})},
        {"0.8 m", testing::lookAt(orbit(0.8, 50, 15), {0, 0, 0})},
    };
    for (const auto& [name, T] : views) {
        const cv::Mat img = scene().render(T);
        const TrackedFrame w =
            single(img, true, nullptr, TrackerOptions{}.coarseFirstMinSidePx, 0.5, true);
        const TrackedFrame whole =
            single(img, true, nullptr, TrackerOptions{}.coarseFirstMinSidePx, 1.0, true);
        std::printf(
            "%s: decimate %.0f, window %dx%d: %d coarse tags, %zu used; whole region "
            "%dx%d: %d coarse tags, %zu used\n",
            name, double(w.coarseFirstDecimate), w.coarseWindow.width, w.coarseWindow.height,
            w.coarseTags, w.estimate.tagsUsed.size(), whole.coarseWindow.width,
            whole.coarseWindow.height, whole.coarseTags, whole.estimate.tagsUsed.size());
        ASSERT_TRUE(w.coarseUsed) << name << ": " << w.estimate.reason;
        ASSERT_TRUE(whole.coarseUsed) << name << ": " << whole.estimate.reason;
        EXPECT_LT(w.coarseWindow.area(), 0.6 * whole.coarseWindow.area()) << name;
        EXPECT_EQ(w.coarseWindow & whole.coarseWindow, w.coarseWindow) << name;
        EXPECT_LT(w.coarseTags, whole.coarseTags) << name;
        EXPECT_EQ(w.estimate.tagsUsed.size(), whole.estimate.tagsUsed.size()) << name;
        EXPECT_LT(rotationDeg(*w.estimate.pose, *whole.estimate.pose), 0.02) << name;
        EXPECT_LT(glm::length(w.estimate.pose->translation - whole.estimate.pose->translation),
                  2e-4)
            << name;
        EXPECT_LT(rotationDeg(*w.estimate.pose, T), 0.1) << name;
    }
    // The central half of the textured region's width and height covered with paper white: the
    // region (the tags left around it) keeps its size, and a window of 0.3 of it about its
    // centre holds no tag.
    cv::Mat covered = scene().render(views[0].second);
    const cv::Rect r = texturedRegion(covered);
    cv::rectangle(covered,
                  cv::Rect(r.x + r.width / 4, r.y + r.height / 4, r.width / 2, r.height / 2),
                  cv::Scalar(255), cv::FILLED);
    const TrackedFrame c =
        single(covered, true, nullptr, TrackerOptions{}.coarseFirstMinSidePx, 0.3);
    const TrackedFrame o = single(covered, false);
    std::printf("centre covered: window %dx%d, %d coarse tags, used %d, %s; ordinary search %s\n",
                c.coarseWindow.width, c.coarseWindow.height, c.coarseTags, int(c.coarseUsed),
                trackingStateName(c.estimate.state), trackingStateName(o.estimate.state));
    EXPECT_TRUE(c.coarseTried);
    EXPECT_EQ(c.coarseTags, 0);
    EXPECT_FALSE(c.coarseUsed);
    ASSERT_EQ(c.estimate.state, o.estimate.state) << c.estimate.reason;
    ASSERT_EQ(c.estimate.pose.has_value(), o.estimate.pose.has_value());
    EXPECT_EQ(c.estimate.tagsUsed, o.estimate.tagsUsed);
    if (c.estimate.pose) {
        EXPECT_EQ(rotationDeg(*c.estimate.pose, *o.estimate.pose), 0.0);
    }
}

}  // namespace
}  // namespace mirage::tracking
