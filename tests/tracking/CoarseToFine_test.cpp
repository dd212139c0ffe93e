// The Tracker's coarse-to-fine search of single frames (TrackerOptions::coarseToFine): libapriltag
// on a strongly decimated image, the pose from its largest tags, the other tags found and
// verified at full resolution from that pose, with a fallback to the ordinary search.
#include <gtest/gtest.h>

#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "testscenes/TrackingViews.h"
#include "tracking/Tracker.h"

namespace mirage::tracking {
namespace {

using Scene = testing::BoardViewScene;
const Scene& scene() {
    return testing::boardViewScene();
}

// One unrelated frame through a fresh Tracker (no previous pose), coarse-to-fine at the fixed
// decimation on or off (the coarse-first choice of the decimation, CoarseFirst_test.cpp, off).
TrackedFrame single(const cv::Mat& img, bool coarseToFine, int coarsePoseTags = 4) {
    const Scene& s = scene();
    TrackerOptions o;
    o.coarseFirst = false;
    o.coarseToFine = coarseToFine;
    o.filterEnabled = false;
    o.coarsePoseTags = coarsePoseTags;
    o.coarseMinWidth = 0;  // the views are 640x480 (off there by default)
    Tracker tracker(s.board, s.cam, o);
    return tracker.process(img, 0.0);
}

double rotationDeg(const Pose& a, const Pose& b) {
    return glm::degrees(rotationAngleBetween(a.rotation, b.rotation));
}

// Views where the decimated search finds large tags: the coarse-to-fine pose is the ordinary
// search's within hundredths of a degree and a fraction of a millimetre, and as close to the
// truth; it uses at least as many tags.
TEST(CoarseToFine, SamePoseAsTheFullSearch) {
    const Scene& s = scene();
    const std::vector<Pose> views = {
        testing::lookAt({0.02, 0.30, 0.01}, {0.01, 0, 0}, {0, 0, -1}, 0.1),
        testing::lookAt({-0.12, 0.39, 0.17}, {0, 0, 0}, {0, 0, -1}, 0.3),
        testing::lookAt({0.15, 0.30, 0.30}, {0.02, 0, 0}, {0, 0, -1}, -0.2),
    };
    for (size_t v = 0; v < views.size(); ++v) {
        const cv::Mat img = s.render(views[v]);
        const TrackedFrame c = single(img, true), o = single(img, false);
        ASSERT_EQ(c.estimate.state, TrackingState::Ok) << v << ": " << c.estimate.reason;
        ASSERT_EQ(o.estimate.state, TrackingState::Ok) << v << ": " << o.estimate.reason;
        EXPECT_TRUE(c.coarseTried);
        EXPECT_TRUE(c.coarseUsed) << v;
        EXPECT_FALSE(o.coarseTried);
        EXPECT_GT(c.coarseTags, 0);
        EXPECT_GE(c.estimate.tagsUsed.size(), o.estimate.tagsUsed.size()) << v;
        const Pose& pc = *c.estimate.pose;
        const Pose& po = *o.estimate.pose;
        const double dRot = rotationDeg(pc, po);
        const double dPos = glm::length(pc.translation - po.translation);
        std::printf(
            "view %zu: coarse %d tags, used %zu vs %zu, rot diff %.4f deg, pos diff %.3f mm, "
            "truth %.4f / %.4f deg\n",
            v, c.coarseTags, c.estimate.tagsUsed.size(), o.estimate.tagsUsed.size(), dRot,
            1e3 * dPos, rotationDeg(pc, views[v]), rotationDeg(po, views[v]));
        EXPECT_LT(dRot, 0.005) << v;
        EXPECT_LT(dPos, 3e-5) << v;
        EXPECT_LT(rotationDeg(pc, views[v]), 0.02) << v;
        EXPECT_LT(glm::length(pc.translation - views[v].translation), 1e-4) << v;
    }
}

// The same pose (tolerance: exactly, the ordinary search ran on the same image).
void expectSamePose(const TrackedFrame& a, const TrackedFrame& b) {
    ASSERT_EQ(a.estimate.state, b.estimate.state) << a.estimate.reason;
    ASSERT_EQ(a.estimate.pose.has_value(), b.estimate.pose.has_value());
    if (!a.estimate.pose) return;
    // 1e-5 deg: the resolution of the angle (acos near 1) for equal poses.
    EXPECT_LT(rotationDeg(*a.estimate.pose, *b.estimate.pose), 1e-5);
    EXPECT_LT(glm::length(a.estimate.pose->translation - b.estimate.pose->translation), 1e-12);
    EXPECT_EQ(a.estimate.tagsUsed, b.estimate.tagsUsed);
}

// A distant, oblique board: its tags are too small for the decimated search, which finds none;
// the frame falls back to the ordinary search and gets exactly its pose.
TEST(CoarseToFine, SmallTagsFallBackToTheOrdinarySearch) {
    const Scene& s = scene();
    const Pose T = testing::lookAt({0.25, 0.34, 0.66}, {0.01, 0, 0}, {0, 1, 0}, 0.1);
    const cv::Mat img = s.render(T);
    const TrackedFrame c = single(img, true), o = single(img, false);
    EXPECT_TRUE(c.coarseTried);
    EXPECT_EQ(c.coarseTags, 0);
    EXPECT_FALSE(c.coarseUsed);
    // 3 small tags: ok or uncertain by their covariance (docs/tracking.md), a pose either way.
    ASSERT_TRUE(o.estimate.pose.has_value()) << o.estimate.reason;
    expectSamePose(c, o);
}

// Coarse poses from a single tag (coarsePoseTags = 1), head-on to oblique: where the planar
// ambiguity of one tag is not settled the frame falls back to the ordinary search and gets
// exactly its pose; where it is settled the pose from all tags is the ordinary search's within
// the bounds above. Never a different pose as ok.
TEST(CoarseToFine, OneTagCoarsePoseIsSettledOrFallsBack) {
    const Scene& s = scene();
    int fellBack = 0, used = 0;
    for (const glm::dvec3& eye : {glm::dvec3(0.01, 0.45, 0.02), glm::dvec3(0.05, 0.6, 0.05),
                                  glm::dvec3(0.1, 0.35, 0.3), glm::dvec3(-0.2, 0.3, 0.25)}) {
        const Pose T = testing::lookAt(eye, {0.01, 0, 0}, {0, 0, -1}, 0.2);
        const cv::Mat img = s.render(T);
        const TrackedFrame c = single(img, true, 1), o = single(img, false);
        ASSERT_EQ(o.estimate.state, TrackingState::Ok) << o.estimate.reason;
        ASSERT_EQ(c.estimate.state, TrackingState::Ok) << c.estimate.reason;
        EXPECT_TRUE(c.coarseTried);
        if (c.coarseUsed) {
            ++used;
            EXPECT_LT(rotationDeg(*c.estimate.pose, *o.estimate.pose), 0.005);
            EXPECT_LT(glm::length(c.estimate.pose->translation - o.estimate.pose->translation),
                      3e-5);
        } else {
            ++fellBack;
            expectSamePose(c, o);
        }
    }
    std::printf("one-tag coarse poses: %d used, %d fell back\n", used, fellBack);
    EXPECT_GT(used, 0);
}

// The fixed-decimation defaults (coarse-first off, as in frames where the textured region is not
// measured: the periodic full search of the video): off at 640x480 (coarseMinWidth 1000), on at
// 1280x720 with the same pose as the decimate-2 search.
TEST(CoarseToFine, DefaultOnlyFrom1000PxWidth) {
    const Scene& s = scene();
    const Pose T = testing::lookAt({-0.12, 0.39, 0.17}, {0, 0, 0}, {0, 0, -1}, 0.3);
    TrackerOptions fixed;
    fixed.coarseFirst = false;
    Tracker small(s.board, s.cam, fixed);
    const TrackedFrame a = small.process(s.render(T), 0.0);
    EXPECT_EQ(a.estimate.state, TrackingState::Ok);
    EXPECT_FALSE(a.coarseTried);
    const CameraIntrinsics hd = testing::pinholeCamera(1280, 720, 1000);
    const cv::Mat img = renderSyntheticBoardView(s.board, s.tex, hd, T);
    Tracker withDefaults(s.board, hd, fixed);
    TrackerOptions off = fixed;
    off.coarseToFine = false;
    Tracker without(s.board, hd, off);
    const TrackedFrame c = withDefaults.process(img, 0.0), o = without.process(img, 0.0);
    ASSERT_EQ(c.estimate.state, TrackingState::Ok) << c.estimate.reason;
    ASSERT_EQ(o.estimate.state, TrackingState::Ok) << o.estimate.reason;
    EXPECT_TRUE(c.coarseUsed);
    EXPECT_LT(rotationDeg(*c.estimate.pose, *o.estimate.pose), 0.005);
    EXPECT_LT(glm::length(c.estimate.pose->translation - o.estimate.pose->translation), 3e-5);
}

// No board: a frame of noise and a blank frame are reported as before (no tag), not ok.
TEST(CoarseToFine, NoTagsUnchanged) {
    cv::Mat noise(480, 640, CV_8UC1);
    cv::RNG rng(7);
    rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
    const cv::Mat blank(480, 640, CV_8UC1, cv::Scalar(128));
    for (const cv::Mat& img : {noise, blank}) {
        const TrackedFrame c = single(img, true), o = single(img, false);
        EXPECT_TRUE(c.coarseTried);
        EXPECT_FALSE(c.coarseUsed);
        EXPECT_NE(c.estimate.state, TrackingState::Ok);
        EXPECT_EQ(c.estimate.state, o.estimate.state);
        EXPECT_FALSE(c.estimate.pose.has_value());
    }
}
}  // namespace
}  // namespace mirage::tracking
