// Board specs parse (and bad ones are refused with a usable message); the chessboard detector
// finds the corners of rendered boards where the camera model put them.
#include <gtest/gtest.h>

#include <random>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include "calibration/CalibrationTarget.h"
#include "calibration/Extrinsics.h"
#include "calibration/SyntheticViews.h"
#include "core/Error.h"
#include "tests/support/TestCameras.h"
#include "tests/support/TestSupport.h"
#include "tracking/BoardImage.h"
#include "tracking/SyntheticBoardView.h"

namespace mirage::calib {
namespace {

TEST(CalibrationTarget, ParsesChessboardSpec) {
    const auto t = CalibrationTarget::parse("chessboard:9x6:0.025");
    EXPECT_EQ(t.kind(), CalibrationTarget::Kind::Chessboard);
    EXPECT_EQ(t.chessboardGeometry().cols, 9);
    EXPECT_EQ(t.chessboardGeometry().rows, 6);
    EXPECT_DOUBLE_EQ(t.chessboardGeometry().squareMetres, 0.025);
    EXPECT_EQ(t.allBoardPoints().size(), 54u);
    EXPECT_NEAR(t.allBoardPoints()[10].x, 0.025, 1e-7);  // (1, 1) row by row
    EXPECT_NEAR(t.allBoardPoints()[10].y, 0.025, 1e-7);
}

TEST(CalibrationTarget, RefusesBadSpecs) {
    for (const char* bad : {"chessboard:9x6", "chessboard:9x:0.02", "chessboard:1x6:0.02",
                            "chessboard:9x6:0", "chessboard:7x7:0.02"}) {
        try {
            CalibrationTarget::parse(bad);
            ADD_FAILURE() << bad << " accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("chessboard"), std::string::npos) << e.what();
        }
    }
    EXPECT_THROW(CalibrationTarget::parse("/no/such/board.json"), Error);
}

// Rendered views: detection error against the exact projections. The renderer ray-casts the
// exact camera model, so this measures the detector (and proves the renderer's pixel
// convention: a half-pixel shift would show as a mean offset of 0.5 px).
TEST(CalibrationTarget, DetectsRenderedChessboardAccurately) {
    const CameraIntrinsics cam = test::distortedWebcam640();
    const ChessboardGeometry board{9, 6, 0.025};
    const auto target = CalibrationTarget::chessboard(board);
    std::mt19937 rng(4);
    PoseSamplerOptions po;
    po.minDistance = 0.3;
    po.maxDistance = 0.5;
    po.marginPx = 12;
    const auto poses = sampleBoardPoses(cam, board, 4, po, rng);
    const ChessboardRenderer renderer(cam, 3);
    double sum2 = 0, n = 0;
    cv::Point2d meanOffset(0, 0);
    for (const auto& pose : poses) {
        const cv::Mat img = renderer.render(board, pose);
        const auto d = target.detect(img, "rendered");
        ASSERT_TRUE(d.found) << d.reason;
        const auto truth = projectView(cam, board, pose, 0.0, rng, "truth");
        ASSERT_EQ(truth.imagePoints.size(), d.view.imagePoints.size());
        // OpenCV may number the corners from either end (a 180-degree symmetric pattern).
        const bool reversed = cv::norm(truth.imagePoints[0] - d.view.imagePoints[0]) >
                              cv::norm(truth.imagePoints[0] - d.view.imagePoints.back());
        for (size_t i = 0; i < truth.imagePoints.size(); ++i) {
            const auto& det = reversed ? d.view.imagePoints[d.view.imagePoints.size() - 1 - i]
                                       : d.view.imagePoints[i];
            const cv::Point2d e = cv::Point2d(det) - cv::Point2d(truth.imagePoints[i]);
            sum2 += e.dot(e);
            meanOffset += e;
            ++n;
        }
    }
    meanOffset *= 1.0 / n;
    const double rms = std::sqrt(sum2 / n);
    RecordProperty("detection_rms_px", std::to_string(rms));
    std::printf("detection RMS %.4f px, mean offset (%.4f, %.4f) px\n", rms, meanOffset.x,
                meanOffset.y);
    EXPECT_LT(rms, 0.12);
    EXPECT_LT(cv::norm(meanOffset), 0.05);
}

TEST(CalibrationTarget, ReportsWhyNothingWasFound) {
    const auto target = CalibrationTarget::parse("chessboard:9x6:0.025");
    const cv::Mat blank(480, 640, CV_8UC1, cv::Scalar(128));
    const auto d = target.detect(blank, "blank.png");
    EXPECT_FALSE(d.found);
    EXPECT_NE(d.reason.find("9x6"), std::string::npos);
}

}  // namespace
}  // namespace mirage::calib

namespace mirage::calib {
namespace {

// mirage's own AprilTag board (data/boards, the same file tracking uses), rendered by tracking's
// synthetic view renderer at sampled poses: detected corners match the projections, and a
// calibration from those views recovers the camera.
TEST(CalibrationTarget, AprilTagBoardViewsCalibrate) {
    const auto boardPath = test::dataDir() / "boards" / "board_4x6_a4.json";
    const auto board = tracking::Board::load(boardPath);
    ASSERT_TRUE(board.sheet);
    const auto target = CalibrationTarget::parse(boardPath.string());
    EXPECT_EQ(target.kind(), CalibrationTarget::Kind::TagBoard);
    EXPECT_EQ(target.allBoardPoints().size(), 4 * board.tags.size());
    const CameraIntrinsics cam =
        test::pinholeCamera(640, 480, 520, 518, 322.5, 238, {-0.2, 0.05, 0.0005, -0.0005, 0.0});
    const auto texture = tracking::renderBoard(board, 4000.0, false);
    // Poses of the sheet's centre region: a 3x3 proxy grid spanning +-s around the centre.
    const double s = 0.09;
    std::mt19937 rng(8);
    PoseSamplerOptions po;
    po.minDistance = 0.35;
    po.maxDistance = 0.5;
    po.imageSpread = 0.5;
    const auto poses = sampleBoardPoses(cam, {3, 3, s}, 8, po, rng);
    std::vector<CalibrationView> views;
    double err2 = 0;
    size_t n = 0;
    for (size_t i = 0; i < poses.size(); ++i) {
        cv::Matx33d R;
        cv::Rodrigues(poses[i].rvec, R);
        // The proxy's origin is at sheet (-s, -s): T_camera_sheet = T_camera_proxy * T_proxy_sheet.
        const cv::Vec3d t = poses[i].tvec + R * cv::Vec3d(s, s, 0);
        const Pose T_camera_sheet = poseFromCv(poses[i].rvec, t);
        const Pose T_world_camera = board.sheet->T_world_sheet * T_camera_sheet.inverse();
        tracking::SyntheticViewOptions vo;
        vo.supersample = 2;
        const cv::Mat img =
            tracking::renderSyntheticBoardView(board, texture, cam, T_world_camera, vo);
        const auto d = target.detect(img, "tags" + std::to_string(i));
        ASSERT_TRUE(d.found) << d.reason;
        // Board plane = sheet frame (target.worldFromBoard() is T_world_sheet).
        const auto projected = projectBoardPoints(d.view.boardPoints, cam, poses[i].rvec, t);
        for (size_t k = 0; k < projected.size(); ++k) {
            const cv::Point2f e = projected[k] - d.view.imagePoints[k];
            err2 += double(e.x) * e.x + double(e.y) * e.y;
            ++n;
        }
        views.push_back(d.view);
        if (i == 0) {
            // The camera's pose in the world from this image alone (true intrinsics): the
            // board file's world, through the sheet frame.
            const auto path = test::outputDir("tagboard_world") / "view0.png";
            ASSERT_TRUE(cv::imwrite(path.string(), img));
            const auto w = poseFromWorldBoard(cam, path.string(), target);
            EXPECT_LT(glm::length(w.T_world_camera.translation - T_world_camera.translation),
                      0.003);
            EXPECT_LT(rotationAngleBetween(w.T_world_camera.rotation, T_world_camera.rotation),
                      0.5 * 0.0174533);
        }
    }
    const double rms = std::sqrt(err2 / double(n));
    std::printf("AprilTag corner RMS against projection: %.3f px over %zu corners\n", rms, n);
    EXPECT_LT(rms, 0.3);
    CalibrationOptions o;
    o.fixK3 = true;
    const auto r = calibrate(views, {cam.width, cam.height}, o);
    EXPECT_TRUE(r.calibration.reliable) << r.calibration.unreliableReason;
    EXPECT_NEAR(r.calibration.intrinsics.fx, cam.fx, 0.01 * cam.fx);
    EXPECT_NEAR(r.calibration.intrinsics.cx, cam.cx, 5.0);
}

}  // namespace
}  // namespace mirage::calib
