#include <gtest/gtest.h>

#include <algorithm>

#include <opencv2/imgcodecs.hpp>

#include "tests/support/TestSupport.h"
#include "tests/tracking/SyntheticViews.h"
#include "tracking/Detector.h"
#include "tracking/PoseEstimator.h"

namespace mirage::tracking {
namespace {
using testing::lookAt;

struct Scene {
    Board board = BoardLayout().makeBoard();
    BoardRaster texture = renderBoard(board, 8000, false);
};
const Scene& scene() {
    static const Scene s;
    return s;
}

struct Result {
    PoseEstimate est;
    double rotErrDeg = 0, transErrRel = 0;
};

Result track(const CameraIntrinsics& cam, const Pose& T_world_camera,
             const std::optional<Pose>& prior = std::nullopt, const Board* board = nullptr,
             const std::string& dump = "") {
    const Scene& s = scene();
    cv::Mat img = renderSyntheticBoardView(s.board, s.texture, cam, T_world_camera);
    if (!dump.empty()) cv::imwrite((test::outputDir("pose_" + dump) / "view.png").string(), img);
    Detector det;
    PoseEstimator pe(board ? *board : s.board, cam);
    Result r;
    r.est = pe.estimate(det.detect(img), prior);
    if (r.est.pose) {
        r.rotErrDeg =
            glm::degrees(rotationAngleBetween(r.est.pose->rotation, T_world_camera.rotation));
        r.transErrRel = glm::length(r.est.pose->translation - T_world_camera.translation) /
                        glm::length(T_world_camera.translation);
    }
    return r;
}

// Reasonable views of the whole board from 0.3-0.5 m at 0-50 degrees: every one ok, median
// rotation error <= 0.1 deg and translation error <= 0.3 % of the distance, never a flip.
TEST(PoseEstimator, AccurateOnReasonableViews) {
    const auto cam = testing::pinholeCamera();
    std::vector<double> rot, trans;
    int i = 0;
    for (double elevDeg : {88.0, 65.0, 45.0}) {
        for (double azDeg : {-30.0, 20.0}) {
            for (double dist : {0.32, 0.45}) {
                const double el = glm::radians(elevDeg), az = glm::radians(azDeg);
                const glm::dvec3 eye = dist * glm::dvec3(std::cos(el) * std::sin(az), std::sin(el),
                                                         std::cos(el) * std::cos(az));
                const Pose T = lookAt(eye, glm::dvec3(0.003, 0, -0.002), glm::dvec3(0, 0, -1),
                                      0.1 * (i++ % 3));
                const Result r = track(cam, T);
                ASSERT_EQ(r.est.state, TrackingState::Ok) << "elev " << elevDeg << " az " << azDeg
                                                          << " d " << dist << ": " << r.est.reason;
                EXPECT_LT(r.rotErrDeg, 1.0) << "flip or gross error at elev " << elevDeg;
                rot.push_back(r.rotErrDeg);
                trans.push_back(r.transErrRel);
            }
        }
    }
    std::sort(rot.begin(), rot.end());
    std::sort(trans.begin(), trans.end());
    const double medRot = rot[rot.size() / 2], medTrans = trans[trans.size() / 2];
    RecordProperty("median_rotation_error_deg", std::to_string(medRot));
    RecordProperty("median_translation_error_rel", std::to_string(medTrans));
    EXPECT_LE(medRot, 0.1);
    EXPECT_LE(medTrans, 0.003);
}

TEST(PoseEstimator, CovarianceIsPositiveAndSmallForAGoodView) {
    const auto cam = testing::pinholeCamera();
    const Result r = track(cam, lookAt({0.05, 0.3, 0.15}, {0, 0, 0}));
    ASSERT_EQ(r.est.state, TrackingState::Ok) << r.est.reason;
    for (int a = 0; a < 6; ++a) {
        const double v = r.est.covariance[size_t(a * 7)];
        EXPECT_GT(v, 0.0);
        // Standard deviations: < 0.1 deg in rotation, < 1 mm in position.
        EXPECT_LT(std::sqrt(v), a < 3 ? glm::radians(0.1) : 1e-3) << "axis " << a;
    }
    EXPECT_GT(r.est.rmsPx, 0.0);
    EXPECT_LT(r.est.rmsPx, 0.5);
}

TEST(PoseEstimator, FisheyeViewIncludingImageEdges) {
    const auto cam = testing::fisheyeCamera();
    // The board centre 62 degrees off the optical axis: its tags span about 45-80 degrees.
    const glm::dvec3 eye(0.0, 0.2, 0.22);
    const glm::dvec3 fwd =
        glm::angleAxis(glm::radians(62.0), glm::dvec3(1, 0, 0)) * glm::normalize(-eye);
    const Pose T = lookAt(eye, eye + fwd, glm::dvec3(0, 1, 0));
    const Result r = track(cam, T, std::nullopt, nullptr, "fisheye");
    ASSERT_EQ(r.est.state, TrackingState::Ok) << r.est.reason;
    EXPECT_GE(r.est.tagsUsed.size(), 6u);
    EXPECT_LT(r.rotErrDeg, 0.3);
    EXPECT_LT(r.transErrRel, 0.005);
}

TEST(PoseEstimator, NoBoardTagsGivesNoTags) {
    PoseEstimator pe(scene().board, testing::pinholeCamera());
    EXPECT_EQ(pe.estimate({}).state, TrackingState::NoTags);
    TagDetection foreign;
    foreign.id = 300;  // not on the board
    foreign.corners = {glm::dvec2(10, 60), {60, 60}, {60, 10}, {10, 10}};
    EXPECT_EQ(pe.estimate({foreign}).state, TrackingState::NoTags);
}

}  // namespace
}  // namespace mirage::tracking
