// `mirage calibrate --batch` end to end: rendered board images in, a calibration file, report
// and ROS export out; bad inputs give clear messages and no file; unobservable data gives a file
// marked unreliable (exit code 2), never a confident one.
#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "calibration/Extrinsics.h"
#include "calibration/SyntheticViews.h"
#include "tests/support/TestCameras.h"
#include "testscenes/CalibrationViews.h"

#include <opencv2/calib3d.hpp>
#include "core/camera/CalibrationFile.h"
#include "tests/support/TestSupport.h"

namespace mirage::calib {
namespace {
namespace fs = std::filesystem;

CameraIntrinsics camera() {
    return test::distortedWebcam640();
}

const ChessboardGeometry kBoard{9, 6, 0.025};

// Renders `poses` into dir/view_NN.png.
void writeViews(const fs::path& dir, const std::vector<BoardPose>& poses) {
    const ChessboardRenderer renderer(camera(), 3);
    for (size_t i = 0; i < poses.size(); ++i) {
        char name[32];
        std::snprintf(name, sizeof name, "view_%02zu.png", i);
        ASSERT_TRUE(cv::imwrite((dir / name).string(), renderer.render(kBoard, poses[i])));
    }
}

std::vector<BoardPose> tiltedPoses(int n) {
    return test::closeBoardPoses(camera(), kBoard, n, 17);
}

TEST(CalibrateCommand, BatchWritesCalibrationReportAndRos) {
    const auto dir = test::outputDir("calibrate_batch");
    const auto images = dir / "images";
    fs::create_directories(images);
    writeViews(images, tiltedPoses(10));
    // A frame without the board is reported, not fatal.
    cv::imwrite((images / "zz_empty.png").string(), cv::Mat(480, 640, CV_8UC1, cv::Scalar(110)));
    const auto out = dir / "cam.yaml", ros = dir / "cam_ros.yaml";
    const auto r =
        test::runMirage({"calibrate", "--batch", images.string(), "--board", "chessboard:9x6:0.025",
                         "-o", out.string(), "--ros", ros.string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("RMS reprojection error"), std::string::npos);
    EXPECT_NE(r.output.find("zz_empty.png"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("verdict: reliable"), std::string::npos);
    const auto cal = loadCalibration(out);
    const auto truth = camera();
    EXPECT_TRUE(cal.reliable);
    EXPECT_EQ(cal.viewCount, 10);
    EXPECT_NEAR(cal.intrinsics.fx, truth.fx, 0.01 * truth.fx);
    EXPECT_NEAR(cal.intrinsics.fy, truth.fy, 0.01 * truth.fy);
    EXPECT_NEAR(cal.intrinsics.cx, truth.cx, 4.0);
    EXPECT_NEAR(cal.intrinsics.cy, truth.cy, 4.0);
    EXPECT_NEAR(cal.intrinsics.coeff(0), truth.coeff(0), 0.02);
    EXPECT_EQ(cal.stdDeviations.size(), 9u);
    EXPECT_EQ(cal.perViewErrors.size(), 10u);
    EXPECT_LT(cal.avgReprojectionError, 0.3);
    EXPECT_TRUE(fs::exists(dir / "cam.yaml.report.txt"));
    EXPECT_TRUE(fs::exists(ros));
}

// A video input: frames sampled (--video-step), named "video.avi#N" in the report.
TEST(CalibrateCommand, BatchFromVideo) {
    const auto dir = test::outputDir("calibrate_video");
    const auto videoPath = dir / "board.avi";
    {
        const ChessboardRenderer renderer(camera(), 2);
        cv::VideoWriter video(videoPath.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0,
                              cv::Size(640, 480), false);
        ASSERT_TRUE(video.isOpened());
        for (const auto& pose : tiltedPoses(8)) {
            const cv::Mat img = renderer.render(kBoard, pose);
            video.write(img);
            video.write(img);  // every second frame is sampled below
        }
    }
    const auto out = dir / "cam.yaml";
    const auto r =
        test::runMirage({"calibrate", "--batch", videoPath.string(), "--board",
                         "chessboard:9x6:0.025", "-o", out.string(), "--video-step", "2"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("board.avi#14"), std::string::npos) << r.output;
    // Progress while a video is read (there was none).
    EXPECT_NE(r.output.find("5 frame(s) read"), std::string::npos) << r.output;
    const auto cal = loadCalibration(out);
    EXPECT_EQ(cal.viewCount, 8);
    EXPECT_NEAR(cal.intrinsics.fx, camera().fx, 0.01 * camera().fx);
}

TEST(CalibrateCommand, TruncatedImageIsRefusedNotTakenAsAView) {
    // libjpeg returns a cut JPEG with its missing rows filled grey ("Premature end of JPEG
    // file" as a warning only), and the old reader took it as a frame.
    const auto dir = test::outputDir("calibrate_truncated");
    const auto images = dir / "images";
    fs::create_directories(images);
    writeViews(images, tiltedPoses(10));
    const cv::Mat view = cv::imread((images / "view_05.png").string());
    fs::remove(images / "view_05.png");
    std::vector<uchar> jpeg;
    cv::imencode(".jpg", view, jpeg);
    jpeg.resize(jpeg.size() * 2 / 3);
    std::ofstream(images / "view_05.jpg", std::ios::binary)
        .write(reinterpret_cast<const char*>(jpeg.data()), std::streamsize(jpeg.size()));
    const auto out = dir / "cam.yaml";
    auto r = test::runMirage({"calibrate", "--batch", images.string(), "--board",
                              "chessboard:9x6:0.025", "-o", out.string()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("view_05.jpg"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("Premature end"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out));
    // A PNG cut short (no IEND chunk) as well.
    fs::remove(images / "view_05.jpg");
    cv::imwrite((images / "view_05.png").string(), view);
    fs::resize_file(images / "view_05.png", fs::file_size(images / "view_05.png") - 12);
    r = test::runMirage({"calibrate", "--batch", images.string(), "--board", "chessboard:9x6:0.025",
                         "-o", out.string()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("view_05.png"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out));
}

TEST(CalibrateCommand, FrontoParallelViewsGiveAnUnreliableFileNotAConfidentOne) {
    const auto dir = test::outputDir("calibrate_fronto");
    const auto images = dir / "images";
    fs::create_directories(images);
    std::vector<BoardPose> poses;
    for (int i = 0; i < 6; ++i) {
        BoardPose p;
        p.rvec = cv::Vec3d(0, 0, 0.04 * i);
        p.tvec = cv::Vec3d(-0.12 + 0.025 * i, -0.07 + 0.015 * i, 0.42 + 0.02 * i);
        poses.push_back(p);
    }
    writeViews(images, poses);
    const auto out = dir / "cam.yaml", ros = dir / "ros.yaml";
    const auto r =
        test::runMirage({"calibrate", "--batch", images.string(), "--board", "chessboard:9x6:0.025",
                         "-o", out.string(), "--ros", ros.string()});
    if (r.exitCode == 1) {
        // Refusing outright is acceptable too, but then no file may exist.
        EXPECT_FALSE(fs::exists(out)) << r.output;
        return;
    }
    ASSERT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("UNRELIABLE"), std::string::npos) << r.output;
    const auto cal = loadCalibration(out);
    EXPECT_FALSE(cal.reliable);
    EXPECT_NE(cal.unreliableReason.find("fronto-parallel"), std::string::npos)
        << cal.unreliableReason;
    EXPECT_FALSE(fs::exists(ros));  // ROS camera_info cannot say "unreliable"
}

TEST(CalibrateCommand, BadInputsAreNamedAndNoFileIsWritten) {
    const auto dir = test::outputDir("calibrate_bad");
    const auto out = dir / "cam.yaml";
    const std::vector<std::string> common = {"--board", "chessboard:9x6:0.025", "-o", out.string()};
    auto run = [&](std::vector<std::string> inputs) {
        std::vector<std::string> args = {"calibrate", "--batch"};
        args.insert(args.end(), inputs.begin(), inputs.end());
        args.insert(args.end(), common.begin(), common.end());
        return test::runMirage(args);
    };
    // Missing file.
    auto r = run({(dir / "missing.png").string()});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.output.find("missing.png"), std::string::npos) << r.output;
    // Corrupt image.
    {
        std::ofstream f(dir / "corrupt.png");
        f << "not a png";
    }
    r = run({(dir / "corrupt.png").string()});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.output.find("corrupt.png"), std::string::npos) << r.output;
    // Not a video although it says so.
    {
        std::ofstream f(dir / "broken.mp4");
        f << "not a video";
    }
    r = run({(dir / "broken.mp4").string()});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.output.find("broken.mp4"), std::string::npos) << r.output;
    // Mixed sizes: both files named.
    cv::imwrite((dir / "a_big.png").string(), cv::Mat(480, 640, CV_8UC1, cv::Scalar(110)));
    cv::imwrite((dir / "b_small.png").string(), cv::Mat(240, 320, CV_8UC1, cv::Scalar(110)));
    r = run({(dir / "a_big.png").string(), (dir / "b_small.png").string()});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.output.find("a_big.png"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("b_small.png"), std::string::npos) << r.output;
    // No board anywhere.
    r = run({(dir / "a_big.png").string()});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.output.find("found in none"), std::string::npos) << r.output;
    // Malformed board spec.
    r = test::runMirage({"calibrate", "--batch", (dir / "a_big.png").string(), "--board",
                         "chessboard:9x6", "-o", out.string()});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.output.find("COLSxROWS"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace mirage::calib

namespace mirage::calib {
namespace {

// Extrinsics end to end: a fish-eye camera beside the pinhole main camera, simultaneous frames
// of the same boards, `--main-calib` + `--main-input`: the file carries T_main_camera.
TEST(CalibrateCommand, FisheyeExtrinsicsRelativeToMainCamera) {
    const auto dir = test::outputDir("calibrate_extrinsics");
    const auto mainDir = dir / "main", fishDir = dir / "fish";
    fs::create_directories(mainDir);
    fs::create_directories(fishDir);
    const auto mainCam = camera();
    const CameraIntrinsics fish =
        test::fisheyeCamera(640, 480, 230, 230, 321, 238, {0.02, -0.01, 0.004, -0.001});
    // T_main_fish: 6 cm to the right, turned 15 degrees to the right (about +Y).
    const cv::Vec3d rMainFish(0, 15 * 0.017453292519943295, 0), tMainFish(0.06, 0, 0);
    cv::Vec3d rFishMain, tFishMain;
    {
        cv::Matx33d R;
        cv::Rodrigues(rMainFish, R);
        cv::Rodrigues(R.t(), rFishMain);
        tFishMain = -(R.t() * tMainFish);
    }
    const ChessboardRenderer mainRenderer(mainCam, 2), fishRenderer(fish, 2);
    const auto poses = tiltedPoses(12);
    for (size_t i = 0; i < poses.size(); ++i) {
        BoardPose fp;
        cv::composeRT(poses[i].rvec, poses[i].tvec, rFishMain, tFishMain, fp.rvec, fp.tvec);
        char name[32];
        std::snprintf(name, sizeof name, "f_%02zu.png", i);
        cv::imwrite((mainDir / name).string(), mainRenderer.render(kBoard, poses[i]));
        cv::imwrite((fishDir / name).string(), fishRenderer.render(kBoard, fp));
    }
    // The main camera's calibration (its truth, as if calibrated before).
    CameraCalibration mainCal;
    mainCal.intrinsics = mainCam;
    saveCalibration(dir / "main.yaml", mainCal);
    const auto out = dir / "fish.yaml";
    const auto r =
        test::runMirage({"calibrate", "--batch", fishDir.string(), "--model", "fisheye", "--board",
                         "chessboard:9x6:0.025", "-o", out.string(), "--main-calib",
                         (dir / "main.yaml").string(), "--main-input", mainDir.string()});
    ASSERT_TRUE(r.exitCode == 0 || r.exitCode == 2) << r.output;
    EXPECT_NE(r.output.find("T_main_camera"), std::string::npos) << r.output;
    const auto cal = loadCalibration(out);
    ASSERT_TRUE(cal.T_parent_camera.has_value());
    EXPECT_EQ(cal.extrinsicParent, "main");
    EXPECT_NEAR(cal.T_parent_camera->translation.x, 0.06, 0.003) << r.output;
    EXPECT_NEAR(cal.T_parent_camera->translation.y, 0.0, 0.003);
    EXPECT_NEAR(cal.T_parent_camera->translation.z, 0.0, 0.003);
    const Pose truth = poseFromCv(rMainFish, tMainFish);
    // The fish-eye intrinsics come from these small boards (16 % of the image): their principal
    // point error (about 1.5 px at f = 230 px, 0.4 deg) dominates the rotation error here.
    EXPECT_LT(rotationAngleBetween(cal.T_parent_camera->rotation, truth.rotation) * 57.3, 0.6);
}

}  // namespace
}  // namespace mirage::calib
