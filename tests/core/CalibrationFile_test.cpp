// Calibration files: both key styles, mirage's additions, round trip, ROS export, bad files.
#include "core/camera/CalibrationFile.h"

#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "core/Error.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

std::filesystem::path calibDir() {
    return test::testDataDir() / "calib";
}

// The FileError message for a bad file; fails the test if loading succeeds.
std::string loadError(const std::filesystem::path& p) {
    try {
        loadCalibration(p);
    } catch (const FileError& e) {
        EXPECT_EQ(e.file(), p.string());
        return e.what();
    }
    ADD_FAILURE() << p << " loaded although it is bad";
    return {};
}

TEST(CalibrationFile, DistortionFreeCameraRoundTrips) {
    // An empty coefficient list means "no distortion"; the file written must load again.
    for (auto model : {DistortionModel::BrownConrady, DistortionModel::KannalaBrandt}) {
        CameraCalibration c;
        c.intrinsics.width = 320;
        c.intrinsics.height = 240;
        c.intrinsics.fx = c.intrinsics.fy = 300;
        c.intrinsics.cx = 160;
        c.intrinsics.cy = 120;
        c.intrinsics.model = model;
        const auto path = test::outputDir("calib_no_distortion") / "cam.yaml";
        saveCalibration(path, c);
        const CameraCalibration back = loadCalibration(path);
        EXPECT_EQ(back.intrinsics.model, model);
        for (double d : back.intrinsics.distortion) EXPECT_EQ(d, 0.0);
        EXPECT_DOUBLE_EQ(back.intrinsics.fx, 300.0);
    }
}

TEST(CalibrationFile, ReadsOpenCvSampleKeys) {
    const CameraCalibration c = loadCalibration(calibDir() / "opencv_sample_style.yaml");
    EXPECT_EQ(c.intrinsics.width, 640);
    EXPECT_EQ(c.intrinsics.height, 480);
    EXPECT_DOUBLE_EQ(c.intrinsics.fx, 612.34567890123);
    EXPECT_DOUBLE_EQ(c.intrinsics.fy, 610.0);
    EXPECT_DOUBLE_EQ(c.intrinsics.cx, 319.5);
    EXPECT_DOUBLE_EQ(c.intrinsics.cy, 239.5);
    EXPECT_EQ(c.intrinsics.model, DistortionModel::BrownConrady);
    ASSERT_EQ(c.intrinsics.distortion.size(), 5u);
    EXPECT_DOUBLE_EQ(c.intrinsics.distortion[0], -0.1);
    EXPECT_DOUBLE_EQ(c.intrinsics.distortion[4], 0.01);
    EXPECT_DOUBLE_EQ(c.avgReprojectionError, 0.25);
    ASSERT_EQ(c.perViewErrors.size(), 3u);
    EXPECT_NEAR(c.perViewErrors[2], 0.3, 1e-6);  // stored as float in the file
    EXPECT_EQ(c.viewCount, 3);
    EXPECT_TRUE(c.reliable);
    EXPECT_FALSE(c.T_parent_camera.has_value());
}

TEST(CalibrationFile, ReadsAFileWrittenByOpenCv) {
    const CameraCalibration c = loadCalibration(calibDir() / "opencv_tutorial_camera_charuco.yml");
    EXPECT_EQ(c.intrinsics.width, 640);
    EXPECT_NEAR(c.intrinsics.fx, 452.51072219637672, 1e-10);
    EXPECT_NEAR(c.intrinsics.cy, 277.75155919135995, 1e-10);
    ASSERT_EQ(c.intrinsics.distortion.size(), 5u);
    EXPECT_NEAR(c.intrinsics.distortion[4], 2.9542589406810080, 1e-12);
    EXPECT_NEAR(c.avgReprojectionError, 0.18234905535936044, 1e-12);
    // The same values as OpenCV's own reader sees.
    cv::FileStorage fs((calibDir() / "opencv_tutorial_camera_charuco.yml").string(),
                       cv::FileStorage::READ);
    cv::Mat k;
    fs["camera_matrix"] >> k;
    EXPECT_EQ(c.intrinsics.fy, k.at<double>(1, 1));
}

TEST(CalibrationFile, ReadsCamelCaseKeys) {
    const CameraCalibration c = loadCalibration(calibDir() / "camelcase_style.yaml");
    EXPECT_EQ(c.intrinsics.width, 1280);
    EXPECT_DOUBLE_EQ(c.intrinsics.fy, 905.0);
    EXPECT_DOUBLE_EQ(c.intrinsics.cy, 360.0);
    ASSERT_EQ(c.intrinsics.distortion.size(), 4u);
    EXPECT_DOUBLE_EQ(c.intrinsics.distortion[1], -0.02);
    EXPECT_LT(c.avgReprojectionError, 0);  // unknown
}

TEST(CalibrationFile, ReadsKdFisheyeWithExtrinsics) {
    const CameraCalibration c = loadCalibration(calibDir() / "kd_fisheye_style.yaml");
    EXPECT_EQ(c.intrinsics.model, DistortionModel::KannalaBrandt);
    EXPECT_DOUBLE_EQ(c.intrinsics.fy, 251.0);
    ASSERT_EQ(c.intrinsics.distortion.size(), 4u);
    EXPECT_FALSE(c.reliable);
    EXPECT_EQ(c.unreliableReason, "only 4 views");
    ASSERT_TRUE(c.T_parent_camera.has_value());
    EXPECT_EQ(c.extrinsicParent, "main");
    // The env camera's +Z axis maps to the main camera's -Y (row 1 of column 2 is -1).
    const glm::dvec3 z = c.T_parent_camera->rotationMatrix() * glm::dvec3(0, 0, 1);
    EXPECT_NEAR(z.y, -1.0, 1e-12);
    EXPECT_NEAR(c.T_parent_camera->translation.y, 0.1, 1e-12);
}

TEST(CalibrationFile, ReadsRosCameraInfo) {
    const CameraCalibration c = loadCalibration(calibDir() / "ros_camera_info.yaml");
    EXPECT_DOUBLE_EQ(c.intrinsics.fx, 500.0);
    EXPECT_DOUBLE_EQ(c.intrinsics.cy, 240.0);
    ASSERT_EQ(c.intrinsics.distortion.size(), 5u);
    EXPECT_DOUBLE_EQ(c.intrinsics.distortion[4], 0.05);
}

CameraCalibration exampleCalibration() {
    CameraCalibration c;
    c.intrinsics.width = 1920;
    c.intrinsics.height = 1080;
    c.intrinsics.fx = 1401.123456789012;
    c.intrinsics.fy = 1399.987654321;
    c.intrinsics.cx = 961.25;
    c.intrinsics.cy = 538.75;
    c.intrinsics.distortion = {0.11, -0.23, 0.0012, -0.0034, 0.087};
    c.avgReprojectionError = 0.31;
    c.perViewErrors = {0.2, 0.3, 0.4, 0.35};
    c.viewCount = 4;
    c.stdDeviations = {0.5, 0.6, 0.3, 0.3, 0.001, 0.002, 1e-5, 1e-5, 0.003};
    c.reliable = false;
    c.unreliableReason = "coverage: top-left corner has no views";
    c.T_parent_camera = Pose::fromRotationTranslation(
        glm::dmat3(glm::mat3_cast(glm::angleAxis(0.3, glm::normalize(glm::dvec3(1, 2, 3))))),
        glm::dvec3(0.05, -0.02, 0.1));
    c.extrinsicParent = "world";
    return c;
}

TEST(CalibrationFile, RoundTripKeepsEverything) {
    const auto dir = test::outputDir("calibration_roundtrip");
    const CameraCalibration a = exampleCalibration();
    saveCalibration(dir / "cam.yaml", a);
    EXPECT_FALSE(std::filesystem::exists(dir / "cam.yaml.tmp"));
    const CameraCalibration b = loadCalibration(dir / "cam.yaml");
    EXPECT_EQ(b.intrinsics.width, a.intrinsics.width);
    EXPECT_EQ(b.intrinsics.height, a.intrinsics.height);
    EXPECT_DOUBLE_EQ(b.intrinsics.fx, a.intrinsics.fx);
    EXPECT_DOUBLE_EQ(b.intrinsics.fy, a.intrinsics.fy);
    EXPECT_DOUBLE_EQ(b.intrinsics.cx, a.intrinsics.cx);
    EXPECT_DOUBLE_EQ(b.intrinsics.cy, a.intrinsics.cy);
    EXPECT_EQ(b.intrinsics.distortion, a.intrinsics.distortion);
    EXPECT_DOUBLE_EQ(b.avgReprojectionError, a.avgReprojectionError);
    EXPECT_EQ(b.perViewErrors, a.perViewErrors);
    EXPECT_EQ(b.stdDeviations, a.stdDeviations);
    EXPECT_EQ(b.viewCount, 4);
    EXPECT_FALSE(b.reliable);
    EXPECT_EQ(b.unreliableReason, a.unreliableReason);
    ASSERT_TRUE(b.T_parent_camera.has_value());
    EXPECT_EQ(b.extrinsicParent, "world");
    // Element-wise: an angle from acos cannot resolve differences below ~1e-8 rad.
    const glm::dmat3 ra = a.T_parent_camera->rotationMatrix(),
                     rb = b.T_parent_camera->rotationMatrix();
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) EXPECT_NEAR(rb[i][j], ra[i][j], 1e-12);
    EXPECT_LT(glm::length(b.T_parent_camera->translation - a.T_parent_camera->translation), 1e-12);

    // OpenCV itself reads the standard keys as the sample's readers do.
    cv::FileStorage fs((dir / "cam.yaml").string(), cv::FileStorage::READ);
    ASSERT_TRUE(fs.isOpened());
    cv::Mat k, d;
    fs["camera_matrix"] >> k;
    fs["distortion_coefficients"] >> d;
    EXPECT_DOUBLE_EQ(k.at<double>(0, 0), a.intrinsics.fx);
    EXPECT_EQ(d.total(), 5u);
    EXPECT_EQ(int(fs["image_width"]), 1920);
}

TEST(CalibrationFile, FisheyeRoundTrip) {
    const auto dir = test::outputDir("calibration_fisheye");
    CameraCalibration a;
    a.intrinsics = {800,
                    800,
                    250,
                    251,
                    400,
                    399,
                    DistortionModel::KannalaBrandt,
                    {0.02, -0.01, 0.003, -0.0005}};
    saveCalibration(dir / "env.yaml", a);
    const CameraCalibration b = loadCalibration(dir / "env.yaml");
    EXPECT_EQ(b.intrinsics.model, DistortionModel::KannalaBrandt);
    EXPECT_EQ(b.intrinsics.distortion, a.intrinsics.distortion);
    EXPECT_TRUE(b.reliable);
    EXPECT_FALSE(b.T_parent_camera.has_value());
}

// The reach (how far off-axis the calibration data went) is saved and read back; files without
// it load with "unknown" (< 0), and a nonsense value names its key.
TEST(CalibrationFile, ReachRoundTripsAndIsOptional) {
    const auto dir = test::outputDir("calibration_reach");
    CameraCalibration a;
    a.intrinsics = {640, 480, 170, 170, 319.5, 239.5, DistortionModel::KannalaBrandt, {0, 0, 0, 0}};
    saveCalibration(dir / "without.yaml", a);
    const CameraCalibration without = loadCalibration(dir / "without.yaml");
    EXPECT_LT(without.reachDeg, 0);
    EXPECT_LT(without.reachRadiusPx, 0);
    a.reachDeg = 81.25;
    a.reachRadiusPx = 223.5;
    saveCalibration(dir / "with.yaml", a);
    const CameraCalibration b = loadCalibration(dir / "with.yaml");
    EXPECT_DOUBLE_EQ(b.reachDeg, 81.25);
    EXPECT_DOUBLE_EQ(b.reachRadiusPx, 223.5);
    {
        std::ofstream out(dir / "bad_reach.yaml");
        out << "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\ncamera_matrix: "
               "!!opencv-matrix\n"
               "   rows: 3\n   cols: 3\n   dt: d\n   data: [ 170., 0., 319.5, 0., 170., 239.5, 0., "
               "0., 1. ]\n"
               "distortion_coefficients: !!opencv-matrix\n   rows: 4\n   cols: 1\n   dt: d\n"
               "   data: [ 0., 0., 0., 0. ]\ndistortion_model: fisheye\nreach_off_axis_deg: -3\n";
    }
    EXPECT_NE(loadError(dir / "bad_reach.yaml").find("reach_off_axis_deg"), std::string::npos);
}

TEST(CalibrationFile, RosExportReadsBack) {
    const auto dir = test::outputDir("calibration_ros");
    const CameraCalibration a = exampleCalibration();
    saveRosCameraInfo(dir / "camera_info.yaml", a, "mirage_main");
    const CameraCalibration b = loadCalibration(dir / "camera_info.yaml");
    EXPECT_DOUBLE_EQ(b.intrinsics.fx, a.intrinsics.fx);
    EXPECT_DOUBLE_EQ(b.intrinsics.cy, a.intrinsics.cy);
    EXPECT_EQ(b.intrinsics.distortion, a.intrinsics.distortion);
    // The fields ROS needs are there, with the projection matrix [K | 0].
    cv::FileStorage fs(
        "%YAML:1.0\n---\n" +
            [&] {
                std::ifstream in(dir / "camera_info.yaml");
                return std::string(std::istreambuf_iterator<char>(in), {});
            }(),
        cv::FileStorage::READ | cv::FileStorage::MEMORY);
    EXPECT_EQ(std::string(fs["camera_name"]), "mirage_main");
    EXPECT_EQ(std::string(fs["distortion_model"]), "plumb_bob");
    EXPECT_EQ(fs["projection_matrix"]["data"].size(), 12u);
    EXPECT_EQ(fs["rectification_matrix"]["data"].size(), 9u);
}

TEST(CalibrationFile, BadFilesNameTheKey) {
    const auto bad = calibDir() / "bad";
    EXPECT_NE(loadError(bad / "missing_camera_matrix.yaml").find("camera_matrix"),
              std::string::npos);
    EXPECT_NE(loadError(bad / "missing_camera_matrix.yaml").find("cameraMatrix"),
              std::string::npos);
    EXPECT_NE(loadError(bad / "camera_matrix_wrong_size.yaml").find("8 values"), std::string::npos);
    EXPECT_NE(loadError(bad / "width_not_a_number.yaml").find("image_width"), std::string::npos);
    EXPECT_NE(loadError(bad / "missing_distortion.yaml").find("distortion_coefficients"),
              std::string::npos);
    EXPECT_NE(loadError(bad / "not_yaml.yaml").find("YAML"), std::string::npos);
    EXPECT_NE(loadError(bad / "negative_focal.yaml").find("focal"), std::string::npos);
    EXPECT_NE(loadError(bad / "extrinsic_not_rigid.yaml").find("T_parent_camera"),
              std::string::npos);
    EXPECT_NE(loadError(bad / "extrinsic_without_parent.yaml").find("extrinsic_parent"),
              std::string::npos);
    EXPECT_NE(loadError(bad / "rational_model.yaml").find("coefficient 6"), std::string::npos);
    EXPECT_NE(loadError(bad / "opencv_tutorial_camera_params_no_size.yml").find("image_width"),
              std::string::npos);
    EXPECT_NE(loadError(bad / "does_not_exist.yaml").find("not found"), std::string::npos);
    // Found by calibration_fuzz: OpenCV's YAML parser throws std::length_error on this file.
    EXPECT_NE(loadError(bad / "parser_length_error.yaml").find("YAML"), std::string::npos);
}

TEST(CalibrationFile, SaveRejectsInvalidIntrinsics) {
    const auto dir = test::outputDir("calibration_invalid");
    CameraCalibration c;  // zero size and focal length
    EXPECT_THROW(saveCalibration(dir / "x.yaml", c), FileError);
    EXPECT_FALSE(std::filesystem::exists(dir / "x.yaml"));
}

}  // namespace
}  // namespace mirage
