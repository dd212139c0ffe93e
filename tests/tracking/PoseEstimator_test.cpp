#include <gtest/gtest.h>

#include <algorithm>

#include <opencv2/imgcodecs.hpp>

#include "tests/support/TestSupport.h"
#include "testscenes/TrackingViews.h"
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

// Detections made by projecting a board's corners (plus Gaussian pixel noise): tests the pose
// stage alone, for boards the sheet renderer cannot draw (non-planar) and for faked outliers.
std::vector<TagDetection> projectedDetections(const Board& b, const CameraIntrinsics& cam,
                                              const Pose& T_world_camera, double sigmaPx,
                                              uint64_t seed) {
    cv::RNG rng(seed);
    std::vector<TagDetection> out;
    const Pose T_cw = T_world_camera.inverse();
    for (const auto& t : b.tags) {
        TagDetection d;
        d.id = t.id;
        bool ok = true;
        auto w = t.cornersInWorld();
        for (int k = 0; k < 4; ++k) {
            auto p = cam.project(T_cw * w[size_t(k)]);
            if (!p || p->x < 0 || p->y < 0 || p->x > cam.width - 1 || p->y > cam.height - 1) {
                ok = false;
                break;
            }
            d.corners[size_t(k)] = *p + glm::dvec2(rng.gaussian(sigmaPx), rng.gaussian(sigmaPx));
        }
        if (ok) out.push_back(d);
    }
    return out;
}

TEST(PoseEstimator, NonPlanarBoardAndOutlierTag) {
    // Two boards at a right angle: the table board and a copy standing up along the far edge
    // (tags 24-47 on the plane z = -0.1, printed side facing +Z: page down = world -Y).
    BoardLayout upright;
    upright.firstId = 24;
    upright.T_world_sheet =
        Pose::fromRotationTranslation(glm::dmat3(1, 0, 0, 0, -1, 0, 0, 0, -1), {0.0, 0.1, -0.1});
    Board b = BoardLayout().makeBoard();
    for (const auto& t : upright.makeBoard().tags) b.tags.push_back(t);
    ASSERT_FALSE(b.isPlanar());
    const auto cam = testing::pinholeCamera();
    const Pose T = lookAt({0.1, 0.35, 0.35}, {0, 0.05, -0.05}, glm::dvec3(0, 1, 0));
    auto dets = projectedDetections(b, cam, T, 0.05, 1);
    ASSERT_GT(dets.size(), 20u);
    // One tag detected at a wrong place (a reflection, a second printout): must be rejected.
    const int wrongId = dets[3].id;
    for (auto& c : dets[3].corners) c += glm::dvec2(25.0, -12.0);
    PoseEstimator pe(b, cam);
    const PoseEstimate e = pe.estimate(dets);
    ASSERT_EQ(e.state, TrackingState::Ok) << e.reason;
    EXPECT_NE(std::find(e.tagsRejected.begin(), e.tagsRejected.end(), wrongId),
              e.tagsRejected.end());
    EXPECT_LT(glm::degrees(rotationAngleBetween(e.pose->rotation, T.rotation)), 0.05);
    EXPECT_LT(glm::length(e.pose->translation - T.translation), 0.0005);
}

// The reported covariance matches the spread of poses over noise draws (Monte Carlo, as mrcal
// checks its uncertainties): the predicted position std is within a factor 1.5 of the observed.
TEST(PoseEstimator, CovarianceMatchesMonteCarloSpread) {
    const Board& b = scene().board;
    const auto cam = testing::pinholeCamera();
    const Pose T = lookAt({0.08, 0.3, 0.22}, {0, 0, 0});
    PoseEstimator pe(b, cam);
    std::vector<glm::dvec3> positions;
    double predictedVar = 0;
    for (int i = 0; i < 60; ++i) {
        const PoseEstimate e = pe.estimate(projectedDetections(b, cam, T, 0.2, 100 + i));
        ASSERT_EQ(e.state, TrackingState::Ok);
        positions.push_back(e.pose->translation);
        predictedVar += (e.covariance[21] + e.covariance[28] + e.covariance[35]) / 60.0;
    }
    glm::dvec3 mean(0.0);
    for (const auto& p : positions) mean += p / double(positions.size());
    double observedVar = 0;
    for (const auto& p : positions)
        observedVar += glm::dot(p - mean, p - mean) / (positions.size() - 1);
    const double ratio = std::sqrt(predictedVar / observedVar);
    RecordProperty("covariance_std_ratio", std::to_string(ratio));
    EXPECT_GT(ratio, 1 / 1.5);
    EXPECT_LT(ratio, 1.5);
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

namespace mirage::tracking {
namespace {

// The refinement's analytic Jacobian (world-frame rotation vector and camera centre; the lens
// part by forward differences inside) against central differences of its residuals through the
// same retraction, for a pinhole with distortion and for a fish-eye, away from the optimum.
TEST(PoseEstimator, RefinementJacobianMatchesFiniteDifferences) {
    const Board& board = scene().board;
    for (const CameraIntrinsics& cam : {testing::pinholeCamera(), testing::fisheyeCamera()}) {
        const Pose truth = lookAt({0.12, 0.38, 0.2}, {0.01, 0.0, -0.02});
        std::vector<TagDetection> dets;
        const Pose T_camera_world = truth.inverse();
        for (const auto& tag : board.tags) {
            TagDetection d;
            d.id = tag.id;
            const auto corners = tag.cornersInWorld();
            bool inView = true;
            for (size_t k = 0; k < 4; ++k) {
                const auto px = cam.project(T_camera_world * corners[k]);
                if (!px) inView = false;
                if (px) d.corners[k] = *px + glm::dvec2(0.3 * std::sin(double(tag.id + k)), 0.2);
            }
            if (inView) dets.push_back(d);
        }
        ASSERT_GE(dets.size(), 4u);
        const lm::Problem problem = poseLeastSquares(board, cam, dets);
        // 1 degree and 5 mm off the truth.
        Pose at = truth;
        at.rotation = glm::normalize(
            glm::angleAxis(glm::radians(1.0), glm::normalize(glm::dvec3(1, 2, 3))) * at.rotation);
        at.translation += glm::dvec3(0.005, -0.003, 0.002);
        const auto x = poseState(at);
        const auto J = lm::denseJacobian(problem, x);
        const auto Jfd = lm::finiteDifferenceJacobian(problem, x, 1e-6);
        ASSERT_EQ(J.size(), Jfd.size());
        ASSERT_EQ(J.size(), dets.size() * 8 * 6);
        double maxAbs = 0, maxDiff = 0;
        for (size_t i = 0; i < J.size(); ++i) {
            maxAbs = std::max(maxAbs, std::abs(Jfd[i]));
            maxDiff = std::max(maxDiff, std::abs(J[i] - Jfd[i]));
        }
        EXPECT_GT(maxAbs, 100.0);  // pixels per radian / metre
        EXPECT_LT(maxDiff, 1e-4 * maxAbs) << "model " << int(cam.model);
        // And the solver brings it back to the noise-level optimum, near the truth.
        auto y = x;
        const lm::Report rep = lm::solve(problem, y);
        EXPECT_TRUE(rep.converged()) << rep.summary();
        EXPECT_LT(glm::degrees(rotationAngleBetween(poseOfState(y).rotation, truth.rotation)), 0.2);
    }
}

}  // namespace
}  // namespace mirage::tracking
