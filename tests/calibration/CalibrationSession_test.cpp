// The wizard's logic without a window: auto-capture decisions on rendered frames (still, moving,
// blurred, similar, held), recalibration after captures, coverage, tilt bins, advice and the
// "done" state.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <opencv2/imgproc.hpp>

#include "calibration/CalibrationSession.h"
#include "calibration/SyntheticViews.h"
#include "tests/support/TestCameras.h"
#include "testscenes/CalibrationViews.h"

namespace mirage::calib {
namespace {

CameraIntrinsics camera() {
    return test::distortedWebcam640();
}

const ChessboardGeometry kBoard{9, 6, 0.025};

std::vector<BoardPose> poses(int n, unsigned seed) {
    return test::closeBoardPoses(camera(), kBoard, n, seed);
}

TEST(CalibrationSession, AutoCaptureNeedsStillSharpAndNewViews) {
    const auto cam = camera();
    const ChessboardRenderer renderer(cam, 2);
    const auto p = poses(2, 1);
    const cv::Mat a = renderer.render(kBoard, p[0]);
    const cv::Mat b = renderer.render(kBoard, p[1]);
    // Out of focus as a lens blurs: in linear light.
    const cv::Mat bBlurred = blurInLinearLight(b, 3.0);

    SessionOptions o;
    o.stillFrames = 3;
    CalibrationSession s(CalibrationTarget::chessboard(kBoard), {cam.width, cam.height}, o);
    using D = CaptureDecision;
    auto decide = [&](const cv::Mat& img) { return s.processFrame(img, "f").decision; };
    // First sight: no motion known yet; then still frames accumulate.
    EXPECT_EQ(decide(a), D::Moving);
    EXPECT_EQ(decide(a), D::Moving);
    EXPECT_EQ(decide(a), D::Moving);
    EXPECT_EQ(decide(a), D::Captured);
    EXPECT_EQ(decide(a), D::Held);  // stays still: no second capture of the same view
    EXPECT_EQ(s.views().size(), 1u);
    // A new pose, out of focus: still but blurred, never captured.
    EXPECT_EQ(decide(bBlurred), D::Moving);
    for (int i = 0; i < 3; ++i) decide(bBlurred);
    EXPECT_EQ(decide(bBlurred), D::Blurred);
    EXPECT_EQ(s.views().size(), 1u);
    // Back into focus (the corners barely move): captured.
    EXPECT_EQ(decide(b), D::Captured);
    EXPECT_EQ(s.views().size(), 2u);
    // The first pose again: still and sharp, but nothing new.
    for (int i = 0; i < 4; ++i) decide(a);
    EXPECT_EQ(decide(a), D::Similar);
    EXPECT_EQ(s.views().size(), 2u);
    // No board at all.
    EXPECT_EQ(decide(cv::Mat(cam.height, cam.width, CV_8UC1, cv::Scalar(110))), D::NoBoard);
}

TEST(CalibrationSession, CollectsUntilDoneWithAdviceOnTheWay) {
    const auto cam = camera();
    std::mt19937 rng(2);
    SessionOptions o;
    CalibrationSession s(CalibrationTarget::chessboard(kBoard), {cam.width, cam.height}, o);
    EXPECT_NE(s.advice().find("Hold the board"), std::string::npos);
    // Fronto-parallel views first: the advice must ask for tilt, and the result is not done.
    for (int i = 0; i < 4; ++i) {
        BoardPose p;
        p.rvec = cv::Vec3d(0, 0, 0.05 * i);
        p.tvec = cv::Vec3d(-0.1 + 0.02 * i, -0.06 + 0.01 * i, 0.45);
        s.addView(projectView(cam, kBoard, p, 0.1, rng, "fronto" + std::to_string(i)));
    }
    EXPECT_EQ(s.state(), CalibrationSession::State::Collecting);
    EXPECT_NE(s.advice().find("Tilt"), std::string::npos) << s.advice();
    ASSERT_TRUE(s.result() || !s.calibrationError().empty());
    if (s.result()) {
        EXPECT_FALSE(s.result()->calibration.reliable);
    }
    EXPECT_EQ(s.tilts().count(TiltCoverage::Fronto), 4);
    // Tilted views all over the image: reaches Done.
    const auto p = poses(16, 3);
    for (size_t i = 0; i < p.size() && s.state() != CalibrationSession::State::Done; ++i)
        s.addView(projectView(cam, kBoard, p[i], 0.1, rng, "tilted" + std::to_string(i)));
    EXPECT_EQ(s.state(), CalibrationSession::State::Done)
        << (s.unmetTargets().empty() ? "" : s.unmetTargets().front());
    EXPECT_TRUE(s.unmetTargets().empty());
    EXPECT_NE(s.advice().find("Done"), std::string::npos);
    EXPECT_GT(s.coverage().coveredFraction(), o.doneCoverage);
    ASSERT_TRUE(s.result());
    EXPECT_NEAR(s.result()->calibration.intrinsics.fx, cam.fx, 0.01 * cam.fx);
    // Dropping views until too few falls back to collecting.
    while (s.views().size() > 5) s.dropView(0);
    EXPECT_EQ(s.state(), CalibrationSession::State::Collecting);
}

TEST(CalibrationSession, OutlierViewIsFlaggedInTheSession) {
    const auto cam = camera();
    std::mt19937 rng(5);
    CalibrationSession s(CalibrationTarget::chessboard(kBoard), {cam.width, cam.height}, {});
    const auto p = poses(10, 6);
    for (size_t i = 0; i < p.size(); ++i) {
        auto v = projectView(cam, kBoard, p[i], 0.1, rng, "v" + std::to_string(i));
        if (i == 7) std::reverse(v.imagePoints.begin(), v.imagePoints.begin() + 20);
        s.addView(v);
    }
    ASSERT_TRUE(s.result());
    EXPECT_TRUE(s.result()->views[7].rejected);
    EXPECT_NE(s.advice().find("outlier"), std::string::npos) << s.advice();
}

TEST(CoverageMap, CountsCellsAndNamesTheEmptiestRegion) {
    CoverageMap m({640, 480}, 8, 6);
    std::vector<cv::Point2f> pts;
    for (float x = 5; x < 320; x += 20)
        for (float y = 5; y < 480; y += 20) pts.emplace_back(x, y);  // left half only
    m.add(pts);
    EXPECT_NEAR(m.coveredFraction(), 0.5, 1e-9);
    std::string name;
    const auto c = m.emptiestRegion(name);
    EXPECT_GT(c.x, 320);
    EXPECT_NE(name.find("right"), std::string::npos) << name;
}

TEST(TiltCoverage, BinsByDirection) {
    EXPECT_EQ(TiltCoverage::binOf(5, 0, 15), TiltCoverage::Fronto);
    EXPECT_EQ(TiltCoverage::binOf(30, 0, 15), TiltCoverage::FacingRight);
    EXPECT_EQ(TiltCoverage::binOf(30, 90, 15), TiltCoverage::FacingDown);
    EXPECT_EQ(TiltCoverage::binOf(30, 180, 15), TiltCoverage::FacingLeft);
    EXPECT_EQ(TiltCoverage::binOf(30, -90, 15), TiltCoverage::FacingUp);
}

TEST(CaptureGate, SharpnessDropsWithBlurAndMotionIsMeasured) {
    const auto cam = camera();
    const ChessboardRenderer renderer(cam, 2);
    const cv::Mat img = renderer.render(kBoard, poses(1, 9)[0]);
    cv::Mat blurred;
    cv::GaussianBlur(img, blurred, cv::Size(), 2.0);
    const cv::Rect roi(0, 0, img.cols, img.rows);
    EXPECT_GT(laplacianVariance(img, roi), 3 * laplacianVariance(blurred, roi));
    // Matched by board point: b leaves out board point 1 (not refined) and moves point 0 by 5 px.
    CalibrationView a, b;
    for (int i = 0; i < 5; ++i) {
        a.boardPoints.emplace_back(0.01f * i, 0.f, 0.f);
        a.imagePoints.emplace_back(10.f * i, 0.f);
        if (i == 1) continue;
        b.boardPoints.push_back(a.boardPoints.back());
        b.imagePoints.push_back(a.imagePoints.back() +
                                (i == 0 ? cv::Point2f(3, 4) : cv::Point2f()));
    }
    EXPECT_NEAR(meanCornerMotion(a, b), 5.0 / 4, 1e-6);
    b.boardPoints.resize(3);
    b.imagePoints.resize(3);
    EXPECT_LT(meanCornerMotion(a, b), 0);  // fewer than 4 shared
    EXPECT_LT(meanCornerMotion(a, {}), 0);
}

// An equidistant fish-eye with a 180-degree image circle inscribed in 640x480 (radius 240 px).
CameraIntrinsics equidistantFisheye() {
    CameraIntrinsics in;
    in.width = 640;
    in.height = 480;
    in.model = DistortionModel::KannalaBrandt;
    in.fx = in.fy = 240.0 / (CV_PI / 2);
    in.cx = 319.5;
    in.cy = 239.5;
    in.distortion.assign(4, 0.0);
    return in;
}

TEST(CoverageMap, FisheyeCountsRingsOffAxisAndNamesTheMissingOnesInDegrees) {
    const auto lens = equidistantFisheye();
    CoverageMap m({640, 480});
    m.setAngularLens(lens);
    ASSERT_TRUE(m.angular());
    EXPECT_EQ(m.reachableRings(), CoverageMap::kRingCount);  // the image's corners are past 90 deg
    // Corners all around, but only within 35 degrees of the axis: the image cells near the
    // centre hold them, and so do the rings 0-20 and 20-40.
    std::vector<cv::Point2f> pts;
    for (double offDeg = 5; offDeg <= 35; offDeg += 10)
        for (double az = 0; az < 360; az += 15) {
            const double off = offDeg * CV_PI / 180, a = az * CV_PI / 180;
            const auto px = lens.project(
                {std::sin(off) * std::cos(a), std::sin(off) * std::sin(a), std::cos(off)});
            ASSERT_TRUE(px);
            pts.emplace_back(float(px->x), float(px->y));
        }
    m.add(pts);
    EXPECT_GT(m.ringCount(0), 0);
    EXPECT_GT(m.ringCount(1), 0);
    EXPECT_EQ(m.ringCount(2), 0);
    EXPECT_EQ(m.ringCount(4), 0);
    EXPECT_NEAR(m.coveredFraction(), 2.0 / 5.0, 1e-9);  // 2 of 5 rings, every sector
    const auto missing = m.missingRings();
    ASSERT_EQ(missing.size(), 1u);
    EXPECT_EQ(missing[0], "no corners beyond 40 deg off-axis yet");
    std::string name;
    const auto c = m.emptiestRegion(name);
    EXPECT_NE(name.find("80+ deg off-axis"), std::string::npos) << name;
    EXPECT_GT(std::hypot(c.x - 319.5, c.y - 239.5), 200.0);  // near the rim, not the centre
    // A gap inside: corners at the rim too leave "between 40 and 80" missing.
    const double off = 85 * CV_PI / 180;
    const auto rim = lens.project({std::sin(off), 0, std::cos(off)});
    ASSERT_TRUE(rim);
    m.add({cv::Point2f(float(rim->x), float(rim->y))});
    ASSERT_EQ(m.missingRings().size(), 1u);
    EXPECT_EQ(m.missingRings()[0], "no corners between 40 and 80 deg off-axis yet");

    // A longer focal length: the image circle overfills the 640 px width and only the image's
    // corners reach past 80 degrees (86 deg along the sector centres): the 80+ ring is not
    // demanded, the 60-80 ring is (in the sectors toward the sides).
    auto wide = lens;
    wide.fx = wide.fy = 230;
    CoverageMap w({640, 480});
    w.setAngularLens(wide);
    EXPECT_EQ(w.reachableRings(), 4);
    EXPECT_TRUE(w.reachable(3, 0));   // 60-80, toward the right
    EXPECT_FALSE(w.reachable(3, 2));  // 60-80, toward the bottom: the border is at 65 deg
    w.add(pts);
    ASSERT_EQ(w.missingRings().size(), 1u);
    EXPECT_EQ(w.missingRings()[0], "no corners beyond 40 deg off-axis yet");
}

TEST(CalibrationSession, FisheyeUnmetTargetsNameTheMissingRingsInDegrees) {
    // Before the first calibration the nominal fish-eye model bins the corners; views near the
    // centre leave the outer rings listed as not done.
    const auto lens = equidistantFisheye();
    SessionOptions o;
    o.calibration.model = DistortionModel::KannalaBrandt;
    CalibrationSession s(CalibrationTarget::chessboard(kBoard), {lens.width, lens.height}, o);
    std::mt19937 rng(3);
    BoardPose p;
    p.rvec = cv::Vec3d(0, 0, 0);
    p.tvec = cv::Vec3d(-0.04, -0.03, 0.6);
    s.addView(projectView(lens, kBoard, p, 0.1, rng, "centre"));
    ASSERT_TRUE(s.coverage().angular());
    const auto unmet = s.unmetTargets();
    EXPECT_NE(std::find(unmet.begin(), unmet.end(), "no corners beyond 20 deg off-axis yet"),
              unmet.end())
        << fmt::format("{}", fmt::join(unmet, " | "));
    std::string region;
    s.coverage().emptiestRegion(region);
    // The nominal lens (diagonal = 180 deg) reaches the 60-80 ring toward the sides, not 80+.
    EXPECT_NE(region.find("60-80 deg off-axis"), std::string::npos) << region;
}

}  // namespace
}  // namespace mirage::calib
