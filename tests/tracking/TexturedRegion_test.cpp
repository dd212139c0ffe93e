// The Tracker's textured-region search of frames without a recent pose (TrackerOptions::
// textureRegion): libapriltag searches only the box of the image blocks with the tags' contrast,
// and the whole image again when that box may have cut off part of the board.
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

// One unrelated frame through a fresh Tracker (no previous pose), the textured region on or off.
// The searches that read only a window about the region (the window retry and the coarse-first
// cascade, WindowRetry_test.cpp) are off: these tests hold the region to the full image's search.
TrackedFrame single(const cv::Mat& img, bool textureRegion, const Board* board = nullptr) {
    TrackerOptions o;
    o.textureRegion = textureRegion;
    o.windowRetry = false;
    o.coarseFirstCascade = false;
    o.filterEnabled = false;
    Tracker tracker(board ? *board : scene().board, scene().cam, o);
    return tracker.process(img, 0.0);
}

double rotationDeg(const Pose& a, const Pose& b) {
    return glm::degrees(rotationAngleBetween(a.rotation, b.rotation));
}

// Image box of the board's tags (with their one-cell quiet zone) under the true pose.
cv::Rect trueTagBox(const Pose& T_world_camera) {
    const Pose T_cw = T_world_camera.inverse();
    double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
    for (const auto& tag : scene().board.tags)
        for (const auto& c : BoardTag::cornersInTag(tag.size * 10.0 / 8.0)) {
            const auto p = scene().cam.project(T_cw * (tag.T_world_tag * c));
            if (!p) continue;
            x0 = std::min(x0, p->x);
            y0 = std::min(y0, p->y);
            x1 = std::max(x1, p->x);
            y1 = std::max(y1, p->y);
        }
    return cv::Rect(cv::Point(int(std::floor(x0)), int(std::floor(y0))),
                    cv::Point(int(std::ceil(x1)) + 1, int(std::ceil(y1)) + 1));
}

TEST(TexturedRegion, BoxHoldsTheBoardOnAPlainBackground) {
    for (const Pose& T : {testing::lookAt(orbit(0.8, 40, -12), {0, 0, 0}),
                          testing::lookAt(orbit(0.6, 25, 30), {0.01, 0, 0}, {0, 0, -1}, 0.3)}) {
        const cv::Mat img = scene().render(T);
        const cv::Rect r = texturedRegion(img);
        const cv::Rect tags = trueTagBox(T) & cv::Rect(0, 0, img.cols, img.rows);
        std::printf("region %dx%d at (%d, %d), tags %dx%d at (%d, %d)\n", r.width, r.height, r.x,
                    r.y, tags.width, tags.height, tags.x, tags.y);
        // Every tag with its quiet zone inside the region (to the 8-px blocks), and the region
        // not much larger than the tags.
        EXPECT_EQ((r & tags), tags);
        EXPECT_LT(r.area(), 1.5 * tags.area() + 16 * (tags.width + tags.height));
    }
    // No contrast: no region; noise: the whole image.
    EXPECT_EQ(texturedRegion(cv::Mat(480, 640, CV_8UC1, cv::Scalar(128))).area(), 0);
    cv::Mat noise(480, 640, CV_8UC1);
    cv::randu(noise, 0, 256);
    EXPECT_GT(texturedRegion(noise).area(), 0.9 * noise.total());
}

// The hard views, as in HardCases: small and distant tags, a steep view, motion blur, an
// occluder, a dark exposure, a board partly outside the image. With the textured region the
// frame gets the pose of the full-image search (the same libapriltag tags: the region's origin
// is aligned to its 8-pixel tiles), or the same non-ok state.
TEST(TexturedRegion, SamePoseAsTheFullImageSearchOnHardViews) {
    struct View {
        const char* name;
        Pose T;
        std::function<void(cv::Mat&)> modify;
        bool regionExpected;
    };
    const std::vector<View> views = {
        {"distant 0.8 m, 40 deg", testing::lookAt(orbit(0.8, 40, 0), {0, 0, 0}), {}, true},
        {"distant 1.1 m", testing::lookAt(orbit(1.1, 80, 0), {0, 0, 0}), {}, true},
        {"steep 70 deg", testing::lookAt(orbit(0.45, 20, 10), {0, 0, 0}, {0, 1, 0}), {}, true},
        {"motion blur 9 px", testing::lookAt(orbit(0.45, 60, 15), {0, 0, 0}),
         [](cv::Mat& img) {
             cv::Mat k = cv::Mat::zeros(1, 9, CV_32F) + 1.0f / 9;
             cv::filter2D(img, img, -1, k);
         },
         true},
        {"occluded", testing::lookAt(orbit(0.6, 65, -10), {0, 0, 0}),
         [](cv::Mat& img) {
             cv::rectangle(img, {0, 0}, {img.cols / 2, img.rows}, cv::Scalar(60), cv::FILLED);
         },
         true},
        {"exposure x0.2", testing::lookAt(orbit(0.6, 60, 5), {0, 0, 0}),
         [](cv::Mat& img) { img.convertTo(img, -1, 0.2, 0); }, true},
        {"board cut by the image edge",
         testing::lookAt(orbit(0.5, 70, 0), {0.12, 0, 0.05}),
         {},
         true},
    };
    for (const View& v : views) {
        cv::Mat img = scene().render(v.T);
        if (v.modify) v.modify(img);
        const TrackedFrame a = single(img, true), b = single(img, false);
        std::printf("%s: %s (region %dx%d, used %d, retry %d), full search %s\n", v.name,
                    trackingStateName(a.estimate.state), a.searchRegion.width,
                    a.searchRegion.height, int(a.textureRegionUsed), int(a.fullFrameRetry),
                    trackingStateName(b.estimate.state));
        EXPECT_EQ(a.textureRegionUsed, v.regionExpected) << v.name;
        ASSERT_EQ(a.estimate.state, b.estimate.state) << v.name << ": " << a.estimate.reason;
        ASSERT_EQ(a.estimate.pose.has_value(), b.estimate.pose.has_value()) << v.name;
        // An uncertain pose is not output (it may rest on other tags from the full search).
        if (a.estimate.state != TrackingState::Ok) continue;
        EXPECT_EQ(a.estimate.tagsUsed.size(), b.estimate.tagsUsed.size()) << v.name;
        EXPECT_LT(rotationDeg(*a.estimate.pose, *b.estimate.pose), 0.02) << v.name;
        EXPECT_LT(glm::length(a.estimate.pose->translation - b.estimate.pose->translation), 2e-4)
            << v.name;
        EXPECT_LT(rotationDeg(*a.estimate.pose, v.T), 0.5) << v.name;
        EXPECT_LT(glm::length(a.estimate.pose->translation - v.T.translation),
                  0.01 * glm::length(v.T.translation))
            << v.name;
    }
}

// Tags in a dim half of the board fall outside the textured region; the pose of the others puts
// the board beyond the region, so the whole image is searched again and all tags are used.
TEST(TexturedRegion, CutOffBoardIsSearchedAgainInFull) {
    const Pose T = testing::lookAt(orbit(0.6, 70, 0), {0, 0, 0});
    cv::Mat img = scene().render(T);
    // The right half in deep shadow: its contrast is under half the lit tags'.
    cv::Mat right = img(cv::Rect(img.cols / 2, 0, img.cols - img.cols / 2, img.rows));
    right.convertTo(right, -1, 0.25, 0);
    const TrackedFrame a = single(img, true), b = single(img, false);
    ASSERT_TRUE(a.textureRegionUsed);
    EXPECT_LT(a.searchRegion.br().x, img.cols / 2 + 24 + 8);
    EXPECT_TRUE(a.fullFrameRetry);
    ASSERT_EQ(a.estimate.state, TrackingState::Ok) << a.estimate.reason;
    ASSERT_EQ(b.estimate.state, TrackingState::Ok) << b.estimate.reason;
    EXPECT_EQ(a.estimate.tagsUsed.size(), b.estimate.tagsUsed.size());
    EXPECT_LT(rotationDeg(*a.estimate.pose, *b.estimate.pose), 1e-5);
}

// Must fail: the region search never turns a wrong board description into a pose. A board file
// with the wrong spacing (the tags do not fit one pose: uncertain at best, never output) or the
// wrong tag family (nothing decodes) gives no ok pose, and the state of the full-image search.
TEST(TexturedRegion, WrongBoardOrFamilyGivesNoPose) {
    const Pose T = testing::lookAt(orbit(0.6, 60, 10), {0, 0, 0});
    const cv::Mat img = scene().render(T);
    BoardLayout wrongGap;
    wrongGap.gap = 0.012;
    BoardLayout wrongFamily;
    wrongFamily.family = "tag25h9";
    wrongFamily.gap = 0.012;
    for (const Board& board : {wrongGap.makeBoard(), wrongFamily.makeBoard()}) {
        const TrackedFrame a = single(img, true, &board);
        std::printf("family %s: %s (%s), region used %d, retry %d\n", board.family.c_str(),
                    trackingStateName(a.estimate.state), a.estimate.reason.c_str(),
                    int(a.textureRegionUsed), int(a.fullFrameRetry));
        EXPECT_TRUE(a.textureRegionUsed);
        EXPECT_NE(a.estimate.state, TrackingState::Ok) << a.estimate.reason;
        EXPECT_EQ(a.estimate.state, single(img, false, &board).estimate.state);
    }
    // The right board on the same frame is found (the comparison above can pass).
    const TrackedFrame ok = single(img, true);
    EXPECT_EQ(ok.estimate.state, TrackingState::Ok) << ok.estimate.reason;
}

}  // namespace
}  // namespace mirage::tracking
