// Fish-eye calibration out to the rim of the image circle, on views rendered through ideal
// equisolid / equidistant lenses (calibration/SyntheticViews.h): the lens fit, corner refinement
// whichever detector found the board, the message for a board too distorted to detect.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "calibration/CalibrationTarget.h"
#include "calibration/Calibrator.h"
#include "calibration/SyntheticViews.h"
#include "tests/support/TestSupport.h"

namespace mirage::calib {
namespace {

constexpr double kDeg = M_PI / 180.0;

cv::Vec3d offAxis(double offDeg, double azimuthDeg) {
    const double t = offDeg * kDeg, a = azimuthDeg * kDeg;
    return {std::sin(t) * std::cos(a), std::sin(t) * std::sin(a), std::cos(t)};
}

glm::dvec3 glmOf(const cv::Vec3d& v) {
    return {v[0], v[1], v[2]};
}

// RMS (pixels) of detected corners against the true projections of the same board points.
double rmsAgainstTruth(const CalibrationView& detected, const CalibrationView& truth) {
    double sum = 0;
    int n = 0;
    for (size_t i = 0; i < detected.boardPoints.size(); ++i)
        for (size_t j = 0; j < truth.boardPoints.size(); ++j)
            if (cv::norm(detected.boardPoints[i] - truth.boardPoints[j]) < 1e-6) {
                const cv::Point2f e = detected.imagePoints[i] - truth.imagePoints[j];
                sum += double(e.dot(e));
                ++n;
            }
    return n ? std::sqrt(sum / n) : 1e9;
}

// The same, for either numbering of the corners (a chessboard is symmetric under 180 degrees).
double rmsEitherWay(const CalibrationView& detected, const CalibrationView& truth) {
    CalibrationView reversed = detected;
    std::reverse(reversed.imagePoints.begin(), reversed.imagePoints.end());
    return std::min(rmsAgainstTruth(detected, truth), rmsAgainstTruth(reversed, truth));
}

TEST(FisheyeRim, IdealLensFitsItsProjection) {
    for (const double fov : {160.0, 180.0, 190.0}) {
        const auto cam = idealFisheye(FisheyeLens::Equisolid, fov, 640, 480);
        double worst = 0;
        for (double t = 0.5; t <= fov / 2; t += 0.5) {
            const auto px = cam.project(glmOf(offAxis(t, 0)));
            ASSERT_TRUE(px) << t;
            worst =
                std::max(worst, std::abs(px->x - cam.cx - 2 * cam.fx * std::sin(0.5 * t * kDeg)));
        }
        EXPECT_LT(worst, 1e-3) << fov;
        // The image circle touches the top and bottom edges.
        EXPECT_NEAR(cam.project(glmOf(offAxis(fov / 2, 90)))->y, cam.cy + 240, 1e-3);
    }
    const auto eq = idealFisheye(FisheyeLens::Equidistant, 180, 640, 480);
    for (double k : eq.distortion) EXPECT_LT(std::abs(k), 1e-9);
}

// A board facing the camera 70 degrees off-axis through a 180-degree equisolid lens: the classic
// detector misses it and the sector-based one finds it; its corners, refined, lie within 0.12 px
// RMS of the truth (the sector-based detector's own corners are 0.29 px off here).
TEST(FisheyeRim, FallbackDetectedCornersAreRefined) {
    const auto cam = idealFisheye(FisheyeLens::Equisolid, 180, 640, 480);
    const ChessboardGeometry board{9, 6, 0.025};
    const auto target = CalibrationTarget::chessboard(board);
    const auto pose = boardPoseFacing(board, offAxis(70, 90), 0.2, 0, 180);
    const cv::Mat img = ChessboardRenderer(cam, 3).render(board, pose);
    std::mt19937 rng(1);
    const auto truth = projectView(cam, board, pose, 0.0, rng, "truth");
    ASSERT_EQ(truth.imagePoints.size(), 54u);
    const auto d = target.detect(img, "rim");
    ASSERT_TRUE(d.found) << d.reason;
    EXPECT_EQ(d.view.detector, "sector-based");
    EXPECT_GE(d.view.imagePoints.size(), 50u);
    const double rms = rmsEitherWay(d.view, truth);
    std::printf("fallback-detected corners: %.3f px RMS from the truth\n", rms);
    EXPECT_LE(rms, 0.12);
}

// Seen whole but too distorted and tilted for either detector: the message says so, instead of
// asking for a board that is already fully visible.
TEST(FisheyeRim, TooDistortedBoardGetsItsOwnMessage) {
    const auto cam = idealFisheye(FisheyeLens::Equisolid, 180, 640, 480);
    const ChessboardGeometry board{9, 6, 0.025};
    const auto target = CalibrationTarget::chessboard(board);
    const auto pose = boardPoseFacing(board, offAxis(60, 180), 0.2, 30, 270);
    const cv::Mat img = ChessboardRenderer(cam, 3).render(board, pose);
    std::mt19937 rng(1);
    ASSERT_EQ(projectView(cam, board, pose, 0.0, rng, "truth").imagePoints.size(), 54u);
    const auto d = target.detect(img, "distorted");
    ASSERT_FALSE(d.found);
    EXPECT_NE(d.reason.find("too distorted"), std::string::npos) << d.reason;
    EXPECT_EQ(d.reason.find("must be visible"), std::string::npos) << d.reason;
}

}  // namespace
}  // namespace mirage::calib
