// Extended tracking from natural features (docs/tracking.md, "Extended tracking"): the pose kept
// when the board leaves the view, never a wrong ok pose when features lie.
//
// The views are rendered in process (core's TexturedPlaneRenderer): the board's sheet pasted into
// a large textured tabletop (value noise, like wood or stone at millimetre scale), seen by a
// camera that orbits the board and then pans away from it until the board is out of view.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include <opencv2/imgproc.hpp>

#include "tests/support/TestSupport.h"
#include "testscenes/TrackingViews.h"
#include "tracking/LandmarkMap.h"
#include "tracking/SyntheticTabletop.h"
#include "tracking/Tracker.h"

namespace mirage::tracking {
namespace {

constexpr double kFps = 30.0;
constexpr int kOrbitFrames = 30, kPanFrames = 36;

const SyntheticTabletop& tabletop() {
    static const SyntheticTabletop t(BoardLayout().makeBoard());
    return t;
}

struct RunResult {
    int frames = 0, ok = 0, wrongOk = 0, featuresOnlyOk = 0, boardOutOfView = 0;
    std::vector<double> rotErrDeg, posErrRel;
    double medianRot() const { return median(rotErrDeg); }
    double medianPos() const { return median(posErrRel); }
    static double median(std::vector<double> v) {
        if (v.empty()) return 0;
        std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
        return v[v.size() / 2];
    }
};

// Runs the tracker over the path; `lie` paints a second textured surface over the left half of
// every frame that moves on its own (3 px right, 1 px down per frame).
RunResult run(const TrackerOptions& options, double panDeg, bool lie) {
    const auto& scene = tabletop();
    const CameraIntrinsics cam = testing::pinholeCamera();
    TexturedPlaneRenderer renderer(cam, 2);
    Tracker tracker(scene.board(), cam, options);
    const cv::Mat liar = valueNoiseTexture(1024, 99);
    RunResult r;
    for (int i = 0; i < kOrbitFrames + kPanFrames; ++i) {
        const Pose T = orbitThenPan(i, kOrbitFrames, kPanFrames, panDeg);
        cv::Mat img = scene.render(renderer, T);
        if (lie) {
            const cv::Mat shift =
                (cv::Mat_<double>(2, 3) << 1, 0, -100 - 3.0 * i, 0, 1, -80 - 1.0 * i);
            cv::Mat moved;
            cv::warpAffine(liar, moved, shift, cv::Size(cam.width / 2, cam.height));
            moved.copyTo(img(cv::Rect(0, 0, cam.width / 2, cam.height)));
        }
        const TrackedFrame f = tracker.process(img, i / kFps);
        ++r.frames;
        r.boardOutOfView += !boardInView(cam, scene.board(), T);
        if (f.estimate.state != TrackingState::Ok) continue;
        ++r.ok;
        r.featuresOnlyOk += f.mode == TrackingMode::FeaturesOnly;
        const double rot =
            glm::degrees(rotationAngleBetween(f.estimate.pose->rotation, T.rotation));
        const double pos =
            glm::length(f.estimate.pose->translation - T.translation) / glm::length(T.translation);
        r.rotErrDeg.push_back(rot);
        r.posErrRel.push_back(pos);
        if (rot > 2.0 || pos > 0.02) {
            ++r.wrongOk;
            ADD_FAILURE() << "frame " << i << " ok but off by " << rot << " deg, " << 100 * pos
                          << " %: " << f.estimate.reason;
        }
    }
    return r;
}

TEST(ExtendedTracking, PanAwayFromTheBoardKeepsTheRightPose) {
    const RunResult r = run({}, 100.0, false);
    // The path takes the board out of view for at least the last eighth of the frames
    // (measured: the last 13 of 66).
    EXPECT_GE(8 * r.boardOutOfView, r.frames);
    // At least 95 % of the frames ok (measured: 63 of 66, 10 of the 13 frames without the board
    // ok from features alone; the last 3 uncertain as the centre's uncertainty passes 0.5 % of
    // the distance). Without the prior on the camera centre (centreAccelSigma = 0): 52.
    EXPECT_GE(100 * r.ok, 95 * r.frames) << r.ok << " of " << r.frames;
    EXPECT_GE(r.featuresOnlyOk, 8);
    EXPECT_LE(r.medianRot(), 0.3);
    EXPECT_LE(r.medianPos(), 0.01);
    EXPECT_EQ(r.wrongOk, 0);
}

TEST(ExtendedTracking, BoardOnlyLosesTheFramesWithoutTheBoard) {
    TrackerOptions o;
    o.features.enabled = false;
    const RunResult r = run(o, 100.0, false);
    EXPECT_LE(r.ok, r.frames - r.boardOutOfView);
    EXPECT_EQ(r.featuresOnlyOk, 0);
    EXPECT_EQ(r.wrongOk, 0);
}

TEST(ExtendedTracking, MovingTexturedObjectOverHalfTheViewNeverGivesAWrongOkPose) {
    const RunResult r = run({}, 100.0, true);
    EXPECT_EQ(r.wrongOk, 0);
    // The board's frames stay ok (the board is in the right half for most of the orbit).
    EXPECT_GT(r.ok, 0);
}

// A frame with nothing to track (an unrelated single frame, the first of a video) defers its
// feature detection to the next frame: single frames pay nothing for features no frame follows,
// while a video's second frame tracks the features of the first as before.
TEST(ExtendedTracking, FeatureDetectionWaitsForAFollowingFrame) {
    const auto& scene = tabletop();
    const CameraIntrinsics cam = testing::pinholeCamera();
    TexturedPlaneRenderer renderer(cam, 2);
    Tracker tracker(scene.board(), cam, {});
    ASSERT_NE(tracker.features(), nullptr);
    const TrackedFrame first =
        tracker.process(scene.render(renderer, orbitThenPan(0, kOrbitFrames, kPanFrames, 80.0)), 0);
    ASSERT_EQ(first.estimate.state, TrackingState::Ok) << first.estimate.reason;
    EXPECT_TRUE(tracker.features()->map().landmarks().empty());
    // A frame 10 s later is unrelated: the deferred detection is dropped, nothing is tracked.
    const TrackedFrame single = tracker.process(
        scene.render(renderer, orbitThenPan(5, kOrbitFrames, kPanFrames, 80.0)), 10);
    ASSERT_EQ(single.estimate.state, TrackingState::Ok) << single.estimate.reason;
    EXPECT_EQ(single.features.tracked, 0);
    EXPECT_TRUE(tracker.features()->map().landmarks().empty());
    // The next frame of a video: the features of the previous frame are detected and tracked.
    const TrackedFrame next = tracker.process(
        scene.render(renderer, orbitThenPan(6, kOrbitFrames, kPanFrames, 80.0)), 10 + 1 / kFps);
    ASSERT_EQ(next.estimate.state, TrackingState::Ok) << next.estimate.reason;
    EXPECT_GE(next.features.tracked, 60);
    EXPECT_GE(tracker.features()->map().landmarks().size(), 60u);
}

// The board alone on a flat background (nothing else to track): the first detection finds fewer
// corners than it looks for, so the refill does not run again in every frame but every
// detectEvery-th (measured: on the benchmark's flat-board video the tracker with features went
// from 3.8 to 1.5 ms per frame at 640x480). Must fail with the refill in every frame (23 of 24
// frames). The textured views refill at once, as the pan tests above show.
TEST(ExtendedTracking, TexturelessViewIsNotSearchedForFeaturesEveryFrame) {
    const auto& s = testing::boardViewScene();
    Tracker tracker(s.board, s.cam, {});
    ASSERT_NE(tracker.features(), nullptr);
    int detections = 0, ok = 0;
    const int frames = 24;
    for (int i = 0; i < frames; ++i) {
        const Pose T = testing::lookAt(testing::orbit(0.45, 60, 10 + 0.5 * i), {0, 0, 0});
        const TrackedFrame f = tracker.process(s.render(T), i / kFps);
        ok += f.estimate.state == TrackingState::Ok;
        detections += f.features.detected >= 0;
    }
    std::printf("%d detections in %d frames (%d ok)\n", detections, frames, ok);
    EXPECT_EQ(ok, frames);
    EXPECT_GE(detections, 1);
    EXPECT_LE(detections, frames / FeatureTrackingOptions{}.detectEvery + 1);
}

// Features tracked over consecutive frames of the orbit, the last one started from a predicted
// pose 4 degrees off (about 35 px at this focal length): the number still tracked.
int trackedAfterABadPrediction(const FeatureTrackingOptions& options) {
    const auto& scene = tabletop();
    const CameraIntrinsics cam = testing::pinholeCamera();
    TexturedPlaneRenderer renderer(cam, 2);
    FeatureTracker features(scene.board(), cam, options);
    auto known = [](const Pose& T) {
        PoseEstimate e;
        e.state = TrackingState::Ok;
        e.pose = T;
        e.distanceM = glm::length(T.translation);
        for (int k = 0; k < 6; ++k) e.covariance[size_t(k * 7)] = k < 3 ? 1e-9 : 1e-8;
        return e;
    };
    cv::Mat grey;
    for (int i = 10; i < 13; ++i) {
        const Pose T = orbitThenPan(i, kOrbitFrames, kPanFrames, 80.0);
        grey = scene.render(renderer, T);
        features.track(grey, T);
        features.learn(grey, known(T), true, cv::Rect());
    }
    const Pose T = orbitThenPan(13, kOrbitFrames, kPanFrames, 80.0);
    Pose wrong = T;
    wrong.rotation = glm::angleAxis(glm::radians(4.0), glm::dvec3(0, 0, 1)) * T.rotation;
    grey = scene.render(renderer, T);
    features.track(grey, wrong);
    return features.stats().tracked;
}

// KLT's first pass searches only the finest pyramid levels (the prediction is usually a few
// pixels off); the tracks it loses are searched again over all levels, so a bad prediction
// loses nothing against searching all levels at once. Must fail: with only the first pass's
// levels (kltLevels 2) most tracks are lost.
TEST(ExtendedTracking, KltRetryOverAllLevelsRecoversABadPrediction) {
    FeatureTrackingOptions allAtOnce;
    allAtOnce.kltFirstLevels = 0;
    const int reference = trackedAfterABadPrediction(allAtOnce);
    const int twoPass = trackedAfterABadPrediction({});
    FeatureTrackingOptions firstPassOnly;
    firstPassOnly.kltLevels = 2;
    const int shallow = trackedAfterABadPrediction(firstPassOnly);
    std::printf(
        "tracked after a 4 deg prediction error: all levels %d, two passes %d, 2 levels %d\n",
        reference, twoPass, shallow);
    ASSERT_GE(reference, 60);
    EXPECT_GE(twoPass, reference - reference / 20);
    EXPECT_LT(shallow, reference / 2);
}

// A landmark seen from two places converges to the true point, with a covariance that covers the
// error; one seen only from one place keeps an uncertain depth but the right direction.
TEST(ExtendedTracking, LandmarkTriangulatesFromKnownPoses) {
    const CameraIntrinsics cam = testing::pinholeCamera();
    const glm::dvec3 X(0.1, 0.02, -0.05);
    LandmarkMap map;
    const Pose A = testing::lookAt({0.0, 0.35, 0.3}, {0, 0, 0});
    const auto pa = cam.project(A.inverse() * X);
    ASSERT_TRUE(pa);
    const int id = map.add(cam, A, *pa, 0.3, 0.0, 0.0, 0.8, 1.0, false);
    ASSERT_GE(id, 0);
    {
        const Landmark& l = *map.find(id);
        EXPECT_LT(glm::length(glm::cross(l.direction, glm::normalize(X - A.translation))), 1e-6);
        EXPECT_GT(std::sqrt(l.covariance[8]), 0.5 / 0.8);  // depth still a guess
    }
    for (int k = 1; k <= 4; ++k) {
        const Pose B = testing::lookAt({0.03 * k, 0.35, 0.3 - 0.01 * k}, {0, 0, 0});
        const auto pb = cam.project(B.inverse() * X);
        ASSERT_TRUE(pb);
        map.observe(id, cam, {B, *pb, 0.3}, 0.004, glm::radians(1.0));
    }
    const Landmark& l = *map.find(id);
    EXPECT_LT(glm::length(l.point() - X), 1e-4);
    EXPECT_LT(l.rmsPx, 1e-3);
    EXPECT_LT(std::sqrt(l.covariance[8]), 0.05 * l.rho);
}

}  // namespace
}  // namespace mirage::tracking
