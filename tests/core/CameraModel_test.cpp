// The camera models match OpenCV's projectPoints (pinhole and fisheye) and invert exactly,
// including far off-axis fish-eye rays.
#include <gtest/gtest.h>

#include <random>

#include <opencv2/calib3d.hpp>

#include "core/camera/CameraModel.h"
#include "tests/support/TestCameras.h"

namespace mirage {
namespace {

CameraIntrinsics pinhole() {
    return test::pinholeCamera(640, 480, 530, 528, 321.5, 242.0,
                               {-0.28, 0.09, 0.001, -0.0005, -0.01});
}

CameraIntrinsics fisheye() {
    return test::fisheyeCamera(1280, 960, 340, 340, 640, 480, {0.03, -0.006, 0.001, -0.0002});
}

TEST(CameraModel, PinholeMatchesOpenCV) {
    auto cam = pinhole();
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    std::vector<cv::Point3d> pts;
    for (int i = 0; i < 200; ++i) pts.push_back({u(rng), u(rng), 1.0 + u(rng)});
    cv::Matx33d K(cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
    std::vector<cv::Point2d> ref;
    cv::projectPoints(pts, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, cam.distortion, ref);
    for (size_t i = 0; i < pts.size(); ++i) {
        auto px = cam.project({pts[i].x, pts[i].y, pts[i].z});
        ASSERT_TRUE(px);
        EXPECT_NEAR(px->x, ref[i].x, 1e-6);
        EXPECT_NEAR(px->y, ref[i].y, 1e-6);
        auto ray = cam.unproject(*px);
        ASSERT_TRUE(ray);
        glm::dvec3 dir = glm::normalize(glm::dvec3(pts[i].x, pts[i].y, pts[i].z));
        EXPECT_NEAR(glm::length(*ray - dir), 0.0, 1e-7);
    }
    EXPECT_FALSE(cam.project({0, 0, -1}));  // behind the camera
    EXPECT_FALSE(cam.project({0, 0, 0}));
}

TEST(CameraModel, FisheyeMatchesOpenCVAndInvertsOffAxis) {
    auto cam = fisheye();
    cv::Matx33d K(cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
    for (double thetaDeg : {0.0, 10.0, 45.0, 70.0, 85.0, 89.0}) {
        double th = thetaDeg * CV_PI / 180;
        cv::Point3d p(std::sin(th) * 0.6, std::sin(th) * 0.8, std::cos(th));
        std::vector<cv::Point3d> in{p};
        std::vector<cv::Point2d> ref;
        cv::fisheye::projectPoints(in, ref, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K,
                                   cam.distortion);
        auto px = cam.project({p.x, p.y, p.z});
        ASSERT_TRUE(px);
        EXPECT_NEAR(px->x, ref[0].x, 1e-6) << thetaDeg;
        EXPECT_NEAR(px->y, ref[0].y, 1e-6) << thetaDeg;
        auto ray = cam.unproject(*px);
        ASSERT_TRUE(ray) << thetaDeg;
        EXPECT_NEAR(glm::length(*ray - glm::dvec3(p.x, p.y, p.z)), 0.0, 1e-8) << thetaDeg;
    }
    // Beyond 90 degrees the model is not trusted: no projection, no NaN.
    EXPECT_FALSE(cam.project({1, 0, -0.5}));
}

// projectWithJacobian: the same pixel as project(), and its derivative against central
// differences (closed form for the pinhole model with all five distortion terms, forward
// differences for the fish-eye model).
TEST(CameraModel, ProjectionJacobianMatchesCentralDifferences) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    for (const CameraIntrinsics& cam : {pinhole(), fisheye()}) {
        for (int i = 0; i < 100; ++i) {
            const glm::dvec3 p(u(rng), u(rng), 1.0 + u(rng));
            glm::dmat3x2 J;
            const auto px = cam.projectWithJacobian(p, J);
            ASSERT_TRUE(px);
            EXPECT_EQ(*px, *cam.project(p));
            for (int a = 0; a < 3; ++a) {
                const double h = 1e-6;
                glm::dvec3 lo = p, hi = p;
                lo[a] -= h;
                hi[a] += h;
                const glm::dvec2 fd = (*cam.project(hi) - *cam.project(lo)) / (2 * h);
                // Pixels per metre: ~500 here; the fish-eye's forward differences are good to
                // ~1e-3 of that.
                const double tol = cam.model == DistortionModel::BrownConrady ? 1e-5 : 0.5;
                EXPECT_NEAR(J[a].x, fd.x, tol) << int(cam.model) << " column " << a;
                EXPECT_NEAR(J[a].y, fd.y, tol) << int(cam.model) << " column " << a;
            }
        }
        glm::dmat3x2 J;
        EXPECT_FALSE(cam.projectWithJacobian({0, 0, -1}, J));
    }
}

TEST(CameraModel, InvalidIntrinsicsDetected) {
    auto cam = pinhole();
    EXPECT_TRUE(cam.isValid());
    cam.fx = std::nan("");
    EXPECT_FALSE(cam.isValid());
}

}  // namespace
}  // namespace mirage
