// Extrinsics: a fish-eye camera's pose relative to a pinhole main camera from simultaneous board
// views (mixed models), and a camera's pose in the world from one board view.
#include <gtest/gtest.h>

#include <random>

#include <opencv2/calib3d.hpp>

#include "calibration/Extrinsics.h"
#include "calibration/SyntheticViews.h"
#include "core/Error.h"
#include "tests/support/TestCameras.h"
#include "tests/support/TestSupport.h"

#include <opencv2/imgcodecs.hpp>

namespace mirage::calib {
namespace {

constexpr double kDeg = 0.017453292519943295;

CameraIntrinsics mainCamera() {
    return test::distortedWebcam640();
}

CameraIntrinsics fisheyeCamera() {
    return test::fisheyeCamera(1280, 800, 380, 380, 640, 400, {0.02, -0.01, 0.004, -0.001});
}

TEST(Extrinsics, FisheyeRelativeToPinholeMainCamera) {
    const auto mainCam = mainCamera(), fish = fisheyeCamera();
    // The fish-eye sits 12 cm to the right, 3 cm up, looking 40 degrees to the right and 10 up.
    cv::Matx33d R;
    cv::Rodrigues(cv::Vec3d(-10 * kDeg, 40 * kDeg, 0), R);
    cv::Vec3d rvecTrue;
    cv::Rodrigues(R, rvecTrue);
    const Pose T_main_fish = poseFromCv(rvecTrue, cv::Vec3d(0.12, -0.03, 0.0));
    const Pose T_fish_main = T_main_fish.inverse();
    const ChessboardGeometry board{9, 6, 0.03};
    std::mt19937 rng(31);
    PoseSamplerOptions po;
    po.minDistance = 0.4;
    po.maxDistance = 0.6;
    po.imageSpread = 0.6;
    const auto poses = sampleBoardPoses(mainCam, board, 12, po, rng);
    std::vector<CalibrationView> mainViews, fishViews;
    for (size_t i = 0; i < poses.size(); ++i) {
        mainViews.push_back(projectView(mainCam, board, poses[i], 0.15, rng, "main"));
        // Board pose in the fish-eye: T_fish_board = T_fish_main * T_main_board.
        const Pose T_fish_board = T_fish_main * poseFromCv(poses[i].rvec, poses[i].tvec);
        const glm::dmat3 m = T_fish_board.rotationMatrix();
        cv::Matx33d Rf;
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) Rf(r, c) = m[c][r];
        BoardPose fp;
        cv::Rodrigues(Rf, fp.rvec);
        fp.tvec = cv::Vec3d(T_fish_board.translation.x, T_fish_board.translation.y,
                            T_fish_board.translation.z);
        fishViews.push_back(projectView(fish, board, fp, 0.15, rng, "fish" + std::to_string(i)));
    }
    const auto e = estimateStereoExtrinsics(mainCam, mainViews, fish, fishViews);
    EXPECT_EQ(e.pairCount, 12);
    const double angleErr = rotationAngleBetween(e.T_main_camera.rotation, T_main_fish.rotation);
    EXPECT_LT(angleErr / kDeg, 0.05);
    EXPECT_LT(glm::length(e.T_main_camera.translation - T_main_fish.translation), 0.0005);
    EXPECT_LT(e.transferRmsPx, 1.0);
    EXPECT_GT(e.rotationSpreadDeg, 0.0);  // noise shows as spread
    // The refined pose's 1-sigma covers its actual error (within 4 sigma), and is not absurd.
    std::printf(
        "extrinsics: rotation error %.4f deg (1-sigma %.4f), translation error %.3f mm "
        "(1-sigma %.3f), per-pair spread %.3f deg %.2f mm\n",
        angleErr / kDeg, e.rotationStdDeg,
        1000 * glm::length(e.T_main_camera.translation - T_main_fish.translation),
        1000 * e.translationStdM, e.rotationSpreadDeg, 1000 * e.translationSpreadM);
    EXPECT_LT(angleErr / kDeg, 4 * e.rotationStdDeg + 1e-3);
    EXPECT_LT(glm::length(e.T_main_camera.translation - T_main_fish.translation),
              4 * e.translationStdM + 1e-5);
    EXPECT_LT(e.rotationStdDeg, 0.2);
    const auto text = formatExtrinsics(e);
    EXPECT_NE(text.find("T_main_camera"), std::string::npos);

    // A chessboard numbered from the other end in one camera (OpenCV's 180-degree ambiguity)
    // makes that pair's pose wrong by 180 degrees: it is dropped, the estimate stays.
    auto flipped = fishViews;
    std::reverse(flipped[3].imagePoints.begin(), flipped[3].imagePoints.end());
    const auto e2 = estimateStereoExtrinsics(mainCam, mainViews, fish, flipped);
    EXPECT_EQ(e2.pairCount, 11);
    ASSERT_EQ(e2.skipped.size(), 1u);
    EXPECT_NE(e2.skipped[0].find("outlier"), std::string::npos);
    EXPECT_LT(rotationAngleBetween(e2.T_main_camera.rotation, T_main_fish.rotation) / kDeg, 0.2);
}

// A chessboard's world is its own frame: T_world_camera = (T_camera_board)^-1.
TEST(Extrinsics, PoseFromWorldBoardImage) {
    const auto cam = mainCamera();
    const ChessboardGeometry board{9, 6, 0.025};
    std::mt19937 rng(41);
    PoseSamplerOptions po;
    po.minDistance = 0.3;
    po.maxDistance = 0.4;
    po.marginPx = 12;
    const auto pose = sampleBoardPoses(cam, board, 1, po, rng)[0];
    const auto dir = test::outputDir("extrinsics_world");
    const auto path = (dir / "world.png").string();
    ASSERT_TRUE(cv::imwrite(path, renderChessboard(cam, board, pose, 3)));
    const auto target = CalibrationTarget::chessboard(board);
    const auto w = poseFromWorldBoard(cam, path, target);
    const Pose truth = poseFromCv(pose.rvec, pose.tvec).inverse();
    EXPECT_LT(w.rmsPx, 0.3);
    // The pattern is 180-degree symmetric: either numbering is a valid board frame, so compare
    // the camera's distance to the board centre and its viewing angle instead of the frame.
    const glm::dvec3 centre(4 * 0.025, 2.5 * 0.025, 0);
    EXPECT_NEAR(glm::length(w.T_world_camera.translation - centre),
                glm::length(truth.translation - centre), 0.002);
    EXPECT_THROW(poseFromWorldBoard(cam, (dir / "missing.png").string(), target), Error);
}

TEST(Extrinsics, MismatchedPairsAreRefused) {
    std::vector<CalibrationView> a(2), b(3);
    EXPECT_THROW(estimateStereoExtrinsics(mainCamera(), a, fisheyeCamera(), b), Error);
}

}  // namespace
}  // namespace mirage::calib
