// ChArUco boards as calibration targets: the spec parser, synthetic views with known intrinsics,
// and OpenCV's own tutorial photos (data/peer/aruco) against OpenCV's gold marker corners and
// reference calibration.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <random>
#include <regex>
#include <sstream>

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "calibration/CalibrationTarget.h"
#include "calibration/Calibrator.h"
#include "calibration/SyntheticViews.h"
#include "core/Error.h"
#include "tests/support/TestCameras.h"
#include "tests/support/TestSupport.h"

namespace mirage::calib {
namespace {

std::string errorOf(const std::string& spec) {
    try {
        CalibrationTarget::parse(spec);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

TEST(Charuco, ParsesSpecsAndRefusesBadOnes) {
    const auto t = CalibrationTarget::parse("charuco:5x7:0.04:0.02:DICT_6X6_250");
    EXPECT_EQ(t.kind(), CalibrationTarget::Kind::Charuco);
    EXPECT_EQ(t.allBoardPoints().size(), size_t(4 * 6));  // inner corners
    EXPECT_NE(t.description().find("ChArUco 5x7"), std::string::npos) << t.description();
    // The dictionary is optional (DICT_6X6_250, OpenCV's tutorial default).
    EXPECT_EQ(CalibrationTarget::parse("charuco:6x8:0.03:0.022").charucoGeometry().dictionary,
              "DICT_6X6_250");

    EXPECT_NE(errorOf("charuco:5x7:0.04:0.02:DICT_9X9_1").find("unknown dictionary"),
              std::string::npos);
    EXPECT_NE(errorOf("charuco:5x7:0.04:0.05").find("smaller than the square"), std::string::npos);
    EXPECT_NE(errorOf("charuco:2x7:0.04:0.02").find("at least 3x3"), std::string::npos);
    EXPECT_NE(errorOf("charuco:5x7").find("SQUARESXxSQUARESY"), std::string::npos);
    // 20x20 squares need 200 markers; DICT_4X4_50 has 50.
    EXPECT_NE(errorOf("charuco:20x20:0.01:0.007:DICT_4X4_50").find("has only 50"),
              std::string::npos);
}

// Rendered views of a printed ChArUco board through a distorted camera: the detected corners
// land on the projections of their board points, and a calibration from them recovers the camera.
TEST(Charuco, SyntheticViewsCalibrate) {
    const CharucoGeometry g{5, 7, 0.04, 0.02, "DICT_6X6_250"};
    const auto target = CalibrationTarget::charuco(g);
    const int texelsPerSquare = 120;
    const cv::Mat texture = target.drawCharuco(texelsPerSquare, 0);
    const CameraIntrinsics cam = test::distortedWebcam640();
    const ChessboardRenderer renderer(cam, 3);
    // Poses of the whole board: a proxy lattice over its outline (6x8 points, 40 mm apart).
    std::mt19937 rng(11);
    PoseSamplerOptions po;
    po.minDistance = 0.4;
    po.maxDistance = 0.6;
    const auto poses = sampleBoardPoses(cam, {6, 8, 0.04}, 8, po, rng);
    std::vector<CalibrationView> views;
    double err2 = 0;
    size_t n = 0;
    for (size_t i = 0; i < poses.size(); ++i) {
        const cv::Mat img =
            renderer.renderTexture(texture, g.squareMetres / texelsPerSquare, {0.0, 0.0}, poses[i]);
        const auto d = target.detect(img, "charuco" + std::to_string(i));
        ASSERT_TRUE(d.found) << d.reason;
        EXPECT_GE(d.view.imagePoints.size(), size_t(20)) << "view " << i;
        const auto projected =
            projectBoardPoints(d.view.boardPoints, cam, poses[i].rvec, poses[i].tvec);
        for (size_t k = 0; k < projected.size(); ++k) {
            const cv::Point2f e = projected[k] - d.view.imagePoints[k];
            err2 += double(e.x) * e.x + double(e.y) * e.y;
            ++n;
        }
        // No constant offset: OpenCV's ChArUco corners come half a pixel off (pixel-corner
        // convention); the target converts them to pixel centres.
        cv::Point2f mean(0, 0);
        for (size_t k = 0; k < projected.size(); ++k) mean += projected[k] - d.view.imagePoints[k];
        mean /= float(projected.size());
        EXPECT_LT(cv::norm(mean), 0.1) << "view " << i << " offset " << mean;
        views.push_back(d.view);
        if (i == 0) cv::imwrite((test::outputDir("charuco") / "view0.png").string(), img);
    }
    const double rms = std::sqrt(err2 / double(n));
    std::printf("ChArUco corner RMS against projection: %.3f px over %zu corners\n", rms, n);
    EXPECT_LT(rms, 0.2);
    const auto r = calibrate(views, {cam.width, cam.height}, {});
    EXPECT_TRUE(r.calibration.reliable) << r.calibration.unreliableReason;
    EXPECT_NEAR(r.calibration.intrinsics.fx, cam.fx, 0.005 * cam.fx);
    EXPECT_NEAR(r.calibration.intrinsics.fy, cam.fy, 0.005 * cam.fy);
    // Eight views pin the principal point down to ~1.5-2 px (1 sigma): within 3 reported sigma.
    ASSERT_EQ(r.calibration.stdDeviations.size(), 9u);
    EXPECT_NEAR(r.calibration.intrinsics.cx, cam.cx, 3 * r.calibration.stdDeviations[2]);
    EXPECT_NEAR(r.calibration.intrinsics.cy, cam.cy, 3 * r.calibration.stdDeviations[3]);
    EXPECT_LT(r.calibration.stdDeviations[3], 3.0);
}

// A view with too little of the board says so instead of calibrating from a handful of points.
TEST(Charuco, BlankImageIsNotFound) {
    const auto target = CalibrationTarget::parse("charuco:5x7:0.04:0.02");
    const auto d = target.detect(cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)), "blank");
    EXPECT_FALSE(d.found);
    EXPECT_NE(d.reason.find("no ChArUco markers"), std::string::npos) << d.reason;
}

struct GoldMarker {
    int id;
    std::array<cv::Point2f, 4> corners;
};

// OpenCV's gold marker corners (integer pixels, +-1 px upstream tolerance) for one image.
std::vector<GoldMarker> goldMarkers(const std::string& image) {
    std::ifstream in(test::dataDir() / "peer" / "aruco" / "expected_charuco_markers.txt");
    EXPECT_TRUE(in) << "expected_charuco_markers.txt missing";
    static const std::regex line(
        R"(([\w.]+), DICT_6X6_250, (\d+), \((\d+) (\d+)\), \((\d+) (\d+)\), \((\d+) (\d+)\), \((\d+) (\d+)\))");
    std::vector<GoldMarker> out;
    std::string s;
    std::smatch m;
    while (std::getline(in, s)) {
        if (!std::regex_match(s, m, line) || m[1] != image) continue;
        GoldMarker g{std::stoi(m[2]), {}};
        for (int c = 0; c < 4; ++c)
            g.corners[size_t(c)] = {std::stof(m[size_t(3 + 2 * c)]),
                                    std::stof(m[size_t(4 + 2 * c)])};
        out.push_back(g);
    }
    return out;
}

cv::FileStorage referenceCalibration() {
    cv::FileStorage fs(
        (test::dataDir() / "peer" / "aruco" / "tutorial_camera_charuco.yml").string(),
        cv::FileStorage::READ);
    EXPECT_TRUE(fs.isOpened());
    return fs;
}

// OpenCV's tutorial photos (img_01 = choriginal, and the partly occluded one): the board pose
// from OpenCV's gold marker corners and OpenCV's reference calibration predicts where every
// ChArUco corner is; mirage's detections must land there. Independent of how mirage detects.
TEST(Charuco, PeerPhotosCornersAgreeWithOpenCvGoldMarkers) {
    const auto target = CalibrationTarget::parse("charuco:5x7:0.04:0.02:DICT_6X6_250");
    auto fs = referenceCalibration();
    cv::Mat K, D;
    fs["camera_matrix"] >> K;
    fs["distortion_coefficients"] >> D;
    const auto board = cv::aruco::CharucoBoard::create(
        5, 7, 0.04f, 0.02f, cv::aruco::getPredefinedDictionary(cv::aruco::DICT_6X6_250));
    size_t cornersUnoccluded = 0;
    for (const std::string name : {"img_01.jpg", "chocclusion_original.jpg"}) {
        const auto gold = goldMarkers(name == "img_01.jpg" ? "choriginal.jpg" : name);
        ASSERT_GE(gold.size(), size_t(10)) << name;
        std::vector<cv::Point3f> object;
        std::vector<cv::Point2f> image;
        for (const auto& g : gold) {
            const auto it = std::find(board->ids.begin(), board->ids.end(), g.id);
            ASSERT_NE(it, board->ids.end());
            const auto& obj = board->objPoints[size_t(it - board->ids.begin())];
            for (size_t c = 0; c < 4; ++c) {
                object.push_back(obj[c]);
                image.push_back(g.corners[c]);
            }
        }
        cv::Vec3d rvec, tvec;
        ASSERT_TRUE(cv::solvePnP(object, image, K, D, rvec, tvec));

        const cv::Mat photo =
            cv::imread((test::dataDir() / "peer" / "aruco" / name).string(), cv::IMREAD_GRAYSCALE);
        ASSERT_FALSE(photo.empty()) << name;
        const auto d = target.detect(photo, name);
        ASSERT_TRUE(d.found) << name << ": " << d.reason;
        std::vector<cv::Point2f> predicted;
        cv::projectPoints(d.view.boardPoints, rvec, tvec, K, D, predicted);
        double worst = 0;
        for (size_t k = 0; k < predicted.size(); ++k)
            worst = std::max(worst, double(cv::norm(predicted[k] - d.view.imagePoints[k])));
        std::printf(
            "%s: %zu ChArUco corners, worst distance to the gold-marker prediction %.2f px\n",
            name.c_str(), predicted.size(), worst);
        EXPECT_LT(worst, 1.0) << name;  // upstream tolerance of the gold corners: 1 px
        if (name == "img_01.jpg") {
            EXPECT_EQ(predicted.size(), size_t(24)) << "the whole board is visible";
            cornersUnoccluded = predicted.size();
        } else {
            EXPECT_LT(predicted.size(), cornersUnoccluded) << "some corners are occluded";
            EXPECT_GE(predicted.size(), size_t(10));
        }
    }
}

// Calibrating from the four tutorial photos lands near OpenCV's reference calibration of the same
// photos (4 views constrain a camera poorly: OpenCV's own calibrateCameraCharuco differs from the
// reference by ~1 % in focal length, see data/peer/aruco/SOURCES.txt).
TEST(Charuco, PeerPhotosCalibrateNearOpenCvReference) {
    const auto target = CalibrationTarget::parse("charuco:5x7:0.04:0.02:DICT_6X6_250");
    std::vector<CalibrationView> views;
    for (int i = 0; i < 4; ++i) {
        const std::string name = "img_0" + std::to_string(i) + ".jpg";
        const cv::Mat photo = cv::imread((test::dataDir() / "peer" / "aruco" / name).string());
        ASSERT_FALSE(photo.empty()) << name;
        const auto d = target.detect(photo, name);
        ASSERT_TRUE(d.found) << name << ": " << d.reason;
        EXPECT_GE(d.view.imagePoints.size(), size_t(20)) << name;
        views.push_back(d.view);
    }
    CalibrationOptions o;
    o.outlierFactor = 1e9;  // four views: keep them all, as the reference did
    const auto r = calibrate(views, {640, 480}, o);
    auto fs = referenceCalibration();
    cv::Mat K;
    fs["camera_matrix"] >> K;
    const auto& c = r.calibration.intrinsics;
    std::printf(
        "ChArUco tutorial: fx %.2f fy %.2f cx %.2f cy %.2f RMS %.3f px (reference %.2f %.2f "
        "%.2f %.2f, 0.182 px)\n",
        c.fx, c.fy, c.cx, c.cy, r.calibration.avgReprojectionError, K.at<double>(0, 0),
        K.at<double>(1, 1), K.at<double>(0, 2), K.at<double>(1, 2));
    EXPECT_NEAR(c.fx, K.at<double>(0, 0), 0.02 * K.at<double>(0, 0));
    EXPECT_NEAR(c.fy, K.at<double>(1, 1), 0.02 * K.at<double>(1, 1));
    EXPECT_NEAR(c.cx, K.at<double>(0, 2), 6.0);
    EXPECT_NEAR(c.cy, K.at<double>(1, 2), 6.0);
    EXPECT_LT(r.calibration.avgReprojectionError, 0.35);
}

}  // namespace
}  // namespace mirage::calib
