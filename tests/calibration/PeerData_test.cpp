// Real calibration data from OpenCV's test suite (data/peer/calib, see data/README.md):
//  - calib1.dat: 7 views of a 7x5 chessboard from a real pinhole camera, with an independent
//    reference from Bouguet's MATLAB toolbox (k1 k2 p1 p2, k3 fixed);
//  - fisheye_left.xml / fisheye_object.xml: 34 views of an 8x6 chessboard from a real fish-eye
//    camera, with OpenCV's reference K, D, RMS and 3-sigma standard errors (test_fisheye.cpp).
#include <gtest/gtest.h>

#include <limits>

#include <fstream>

#include <opencv2/core.hpp>

#include "calibration/Calibrator.h"
#include "tests/support/TestSupport.h"

namespace mirage::calib {
namespace {

std::filesystem::path peerDir() {
    return test::dataDir() / "peer" / "calib";
}

std::vector<CalibrationView> loadCalib1(cv::Size& size) {
    std::ifstream in(peerDir() / "calib1.dat");
    EXPECT_TRUE(in.good());
    int w, h, cols, rows, n, flags, fixedPoint;
    in >> w >> h >> cols >> rows >> n >> flags >> fixedPoint;
    size = {w, h};
    std::vector<CalibrationView> views(static_cast<size_t>(n));
    for (int v = 0; v < n; ++v)
        for (int i = 0; i < cols * rows; ++i) {
            double x, y, z;
            in >> x >> y >> z;  // centimetres (2.54 cm squares)
            views[size_t(v)].boardPoints.emplace_back(float(x / 100), float(y / 100), float(z));
        }
    for (int v = 0; v < n; ++v) {
        views[size_t(v)].name = "calib1 view " + std::to_string(v);
        for (int i = 0; i < cols * rows; ++i) {
            double x, y;
            in >> x >> y;
            views[size_t(v)].imagePoints.emplace_back(float(x), float(y));
        }
    }
    return views;
}

TEST(PeerData, OpenCvCalib1MatchesBouguetReference) {
    cv::Size size;
    const auto views = loadCalib1(size);
    ASSERT_EQ(views.size(), 7u);
    CalibrationOptions o;
    o.fixK3 = true;  // the reference's flags (CALIB_FIX_K3..K6)
    const auto r = calibrate(views, size, o);
    const auto& k = r.calibration.intrinsics;
    // Bouguet's toolbox: fc, cc, kc printed to 5 decimals; OpenCV 4.6 agrees to ~1e-3 px.
    EXPECT_NEAR(k.fx, 809.94790, 0.01);
    EXPECT_NEAR(k.fy, 806.55964, 0.01);
    EXPECT_NEAR(k.cx, 361.99611, 0.01);
    EXPECT_NEAR(k.cy, 214.39514, 0.01);
    EXPECT_NEAR(k.coeff(0), -0.12821, 5e-5);
    EXPECT_NEAR(k.coeff(1), -0.39441, 5e-5);
    EXPECT_NEAR(k.coeff(2), -0.00435, 5e-5);
    EXPECT_NEAR(k.coeff(3), -0.00732, 5e-5);
    EXPECT_EQ(k.coeff(4), 0.0);
    EXPECT_NEAR(r.calibration.avgReprojectionError, 0.13889, 1e-3);
    EXPECT_EQ(r.usedViewCount(), 7);
    EXPECT_TRUE(r.calibration.reliable) << r.calibration.unreliableReason;
    std::printf("calib1: fx %.5f fy %.5f cx %.5f cy %.5f k %.5f %.5f %.5f %.5f RMS %.5f\n", k.fx,
                k.fy, k.cx, k.cy, k.coeff(0), k.coeff(1), k.coeff(2), k.coeff(3),
                r.calibration.avgReprojectionError);
    const auto& sd = r.calibration.stdDeviations;
    std::printf("calib1 1-sigma: fx %.4f fy %.4f cx %.4f cy %.4f\n", sd[0], sd[1], sd[2], sd[3]);
}

std::vector<CalibrationView> loadFisheye() {
    cv::FileStorage left((peerDir() / "fisheye_left.xml").string(), cv::FileStorage::READ);
    cv::FileStorage object((peerDir() / "fisheye_object.xml").string(), cv::FileStorage::READ);
    EXPECT_TRUE(left.isOpened() && object.isOpened());
    std::vector<CalibrationView> views;
    for (int i = 0;; ++i) {
        const std::string key = "image_" + std::to_string(i);
        const cv::FileNode img = left[key], obj = object[key];
        if (img.empty() || obj.empty()) break;
        std::vector<double> xy, xyz;
        for (const auto& v : img) xy.push_back(double(v));
        for (const auto& v : obj) xyz.push_back(double(v));
        CalibrationView view;
        view.name = key;
        for (size_t p = 0; p + 1 < xy.size(); p += 2)
            view.imagePoints.emplace_back(float(xy[p]), float(xy[p + 1]));
        for (size_t p = 0; p + 2 < xyz.size(); p += 3)
            view.boardPoints.emplace_back(float(xyz[p]), float(xyz[p + 1]), float(xyz[p + 2]));
        views.push_back(std::move(view));
    }
    return views;
}

TEST(PeerData, OpenCvFisheyeMatchesReference) {
    const auto views = loadFisheye();
    ASSERT_EQ(views.size(), 34u);
    ASSERT_EQ(views[0].imagePoints.size(), 48u);
    CalibrationOptions o;
    o.model = DistortionModel::KannalaBrandt;
    {
        // mirage's defaults drop outlier corners and down-weight noisy views, which OpenCV does
        // not do: printed for docs/calibration.md.
        const auto robust = calibrate(views, {1280, 800}, o);
        int weighted = 0;
        for (const auto& v : robust.views) weighted += v.weight < 1 ? 1 : 0;
        std::printf(
            "defaults: %d corners dropped, %d views down-weighted, fx %.3f fy %.3f cx %.3f "
            "cy %.3f, RMS %.4f px\n",
            robust.droppedCornerCount, weighted, robust.calibration.intrinsics.fx,
            robust.calibration.intrinsics.fy, robust.calibration.intrinsics.cx,
            robust.calibration.intrinsics.cy, robust.calibration.avgReprojectionError);
    }
    // The same solver as OpenCV's: no corner rejection, equal weights.
    o.cornerOutlierSigmas = std::numeric_limits<double>::infinity();
    o.weightViewsByNoise = false;
    const auto r = calibrate(views, {1280, 800}, o);
    const auto& k = r.calibration.intrinsics;
    EXPECT_EQ(r.usedViewCount(), 34);
    EXPECT_EQ(r.droppedCornerCount, 0);
    // OpenCV's reference (test_fisheye.cpp). Tolerances: 0.05 px on K (a tenth of its 1-sigma
    // uncertainty), 2e-4 on D, 1e-3 px on the RMS.
    EXPECT_NEAR(k.fx, 558.478087865323, 0.05);
    EXPECT_NEAR(k.fy, 560.506767351568, 0.05);
    EXPECT_NEAR(k.cx, 620.458515360843, 0.05);
    EXPECT_NEAR(k.cy, 381.939424848348, 0.05);
    EXPECT_NEAR(k.coeff(0), -0.0014613319981768, 2e-4);
    EXPECT_NEAR(k.coeff(1), -0.00329861110580401, 2e-4);
    EXPECT_NEAR(k.coeff(2), 0.00605760088590183, 2e-4);
    EXPECT_NEAR(k.coeff(3), -0.00374209380722371, 2e-4);
    EXPECT_NEAR(r.calibration.avgReprojectionError, 0.263782587133546, 1e-3);
    std::printf("fisheye: fx %.6f fy %.6f cx %.6f cy %.6f D %.7f %.7f %.7f %.7f RMS %.9f\n", k.fx,
                k.fy, k.cx, k.cy, k.coeff(0), k.coeff(1), k.coeff(2), k.coeff(3),
                r.calibration.avgReprojectionError);
    std::printf("fisheye 1-sigma: fx %.4f fy %.4f cx %.4f cy %.4f\n",
                r.calibration.stdDeviations[0], r.calibration.stdDeviations[1],
                r.calibration.stdDeviations[2], r.calibration.stdDeviations[3]);
    // OpenCV's "standard errors" are 3 sigma (EstimateUncertainties); ours are 1 sigma.
    const auto& sd = r.calibration.stdDeviations;
    EXPECT_NEAR(sd[0], 1.3425 / 3, 0.1 * 1.3425 / 3);
    EXPECT_NEAR(sd[1], 1.3604 / 3, 0.1 * 1.3604 / 3);
    EXPECT_NEAR(sd[2], 0.9207 / 3, 0.1 * 0.9207 / 3);
    EXPECT_NEAR(sd[3], 0.8438 / 3, 0.1 * 0.8438 / 3);
    EXPECT_TRUE(r.calibration.reliable) << r.calibration.unreliableReason;
}

}  // namespace
}  // namespace mirage::calib
