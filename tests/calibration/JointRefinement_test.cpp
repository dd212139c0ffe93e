// The calibration's least-squares problems (core/math/LevenbergMarquardt.h): the joint
// intrinsics + view poses problem and the stereo extrinsics problem. Their analytic Jacobians
// against central differences of their residuals, for the pinhole and the fish-eye model.
#include <gtest/gtest.h>

#include <random>

#include "calibration/Extrinsics.h"
#include "calibration/JointRefinement.h"
#include "calibration/SyntheticViews.h"
#include "tests/support/TestCameras.h"

namespace mirage::calib {
namespace {

CameraIntrinsics fisheye() {
    return test::fisheyeCamera(1280, 800, 380, 380, 640, 400, {0.02, -0.01, 0.004, -0.001});
}

std::vector<CalibrationView> views(const CameraIntrinsics& cam, int count, unsigned seed) {
    const ChessboardGeometry board{7, 5, 0.03};
    std::mt19937 rng(seed);
    const auto poses = sampleBoardPoses(cam, board, count, PoseSamplerOptions{}, rng);
    std::vector<CalibrationView> out;
    for (const auto& p : poses) out.push_back(projectView(cam, board, p, 0.2, rng, "view"));
    return out;
}

// Largest |J - J_fd| relative to the largest |J_fd| entry of its column: columns differ by
// orders of magnitude (pixels per focal pixel vs pixels per distortion unit).
double worstColumnError(const lm::Problem& p, const std::vector<double>& x, double h) {
    const auto J = lm::denseJacobian(p, x), Jfd = lm::finiteDifferenceJacobian(p, x, h);
    EXPECT_EQ(J.size(), Jfd.size());
    const size_t P = size_t(p.parameters), m = J.size() / P;
    double worst = 0;
    for (size_t c = 0; c < P; ++c) {
        double scale = 0, diff = 0;
        for (size_t r = 0; r < m; ++r) {
            scale = std::max(scale, std::abs(Jfd[r * P + c]));
            diff = std::max(diff, std::abs(J[r * P + c] - Jfd[r * P + c]));
        }
        EXPECT_GT(scale, 0.0) << "column " << c << " is all zero";
        worst = std::max(worst, diff / std::max(scale, 1e-300));
    }
    return worst;
}

TEST(JointRefinement, JacobianMatchesFiniteDifferences) {
    for (const CameraIntrinsics& cam : {test::distortedWebcam640(), fisheye()}) {
        const auto vs = views(cam, 4, 5);
        JointProblem p;
        for (const auto& v : vs) p.views.push_back(&v);
        p.intrinsics = cam;
        std::mt19937 rng(3);
        for (const auto* v : p.views) {
            cv::Vec3d r, t;
            ASSERT_TRUE(estimateBoardPose(*v, cam, r, t));
            p.rvecs.push_back(r + cv::Vec3d(0.01, -0.02, 0.005));
            p.tvecs.push_back(t + cv::Vec3d(0.002, 0.001, -0.004));
        }
        // Off the optimum, and with k3 held fixed for the pinhole (as fixK3 does).
        p.intrinsics.fx *= 1.01;
        p.intrinsics.cx += 3;
        if (cam.model == DistortionModel::BrownConrady)
            p.fixedIntrinsics = {false, false, false, false, false, false, false, false, true};
        const lm::Problem ls = leastSquares(p);
        EXPECT_EQ(ls.parameters, 8 + 24);  // 9 pinhole intrinsics with k3 fixed, or 8 fish-eye
        EXPECT_LT(worstColumnError(ls, stateOf(p), 1e-6), 1e-4) << "model " << int(cam.model);
        // The solver then lands on the noise floor (0.2 px per coordinate).
        const double rms = refineJointly(p, 50);
        EXPECT_LT(rms, 0.4);
        EXPECT_NEAR(p.intrinsics.fx, cam.fx, 0.01 * cam.fx);
    }
}

TEST(Extrinsics, JacobianMatchesFiniteDifferences) {
    const CameraIntrinsics main = test::distortedWebcam640(), cam = fisheye();
    const auto mv = views(main, 3, 8), cv_ = views(cam, 3, 9);  // poses need not agree here
    std::vector<const CalibrationView*> a, b;
    for (size_t i = 0; i < mv.size(); ++i) {
        a.push_back(&mv[i]);
        b.push_back(&cv_[i]);
    }
    const lm::Problem ls = stereoLeastSquares(main, cam, a, b);
    ASSERT_EQ(ls.parameters, 6 + 6 * 3);
    std::vector<double> x = {0.1, -0.6, 0.05, 0.12, -0.03, 0.01};
    for (const auto* v : a) {
        cv::Vec3d r, t;
        ASSERT_TRUE(estimateBoardPose(*v, main, r, t));
        x.insert(x.end(), {r[0], r[1], r[2], t[0], t[1], t[2]});
    }
    EXPECT_LT(worstColumnError(ls, x, 1e-6), 1e-4);
}

}  // namespace
}  // namespace mirage::calib
