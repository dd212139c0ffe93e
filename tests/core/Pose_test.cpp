#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "core/math/Pose.h"

namespace mirage {
namespace {

TEST(Pose, ComposeAndInverse) {
    Pose a = Pose::fromMatrix(glm::rotate(glm::translate(glm::dmat4(1), {1, 2, 3}), 0.7,
                                          glm::normalize(glm::dvec3(1, 1, 0))));
    Pose b = Pose::fromMatrix(
        glm::rotate(glm::translate(glm::dmat4(1), {-0.5, 0, 2}), -1.2, glm::dvec3(0, 0, 1)));
    glm::dvec3 p(0.3, -0.2, 5.0);
    // T_a_c = T_a_b * T_b_c applied to p equals applying them in turn.
    glm::dvec3 viaCompose = (a * b) * p, inTurn = a * (b * p);
    EXPECT_NEAR(glm::length(viaCompose - inTurn), 0.0, 1e-12);
    glm::dvec3 back = a.inverse() * (a * p);
    EXPECT_NEAR(glm::length(back - p), 0.0, 1e-12);
    EXPECT_NEAR(rotationAngleBetween((a * a.inverse()).rotation, Pose().rotation), 0.0, 1e-7);
}

TEST(Pose, MatrixRoundTrip) {
    glm::dmat4 m = glm::rotate(glm::translate(glm::dmat4(1), {4, 5, 6}), 2.5, glm::dvec3(0, 1, 0));
    glm::dmat4 r = Pose::fromMatrix(m).matrix();
    for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 4; ++k) EXPECT_NEAR(r[c][k], m[c][k], 1e-12);
}

TEST(Pose, QuaternionSignDoesNotMatterForAngle) {
    glm::dquat q = glm::angleAxis(0.3, glm::dvec3(0, 0, 1));
    EXPECT_NEAR(rotationAngleBetween(q, -q), 0.0, 1e-7);
    EXPECT_NEAR(rotationAngleBetween(q, glm::dquat(1, 0, 0, 0)), 0.3, 1e-12);
}

TEST(Pose, CvFromGltfCameraFlipsYZ) {
    // A glTF camera looks down -Z; in OpenCV axes that direction is +Z.
    glm::dvec3 forwardCv = kCvFromGltfCamera * glm::dvec3(0, 0, 1);
    EXPECT_NEAR(forwardCv.z, -1.0, 1e-12);
    Pose twice = kCvFromGltfCamera * kCvFromGltfCamera;
    EXPECT_NEAR(rotationAngleBetween(twice.rotation, Pose().rotation), 0.0, 1e-7);
}

TEST(Pose, RotationVectorAndBackIsTheSameRotation) {
    // Small, ordinary and near-pi angles; q and -q give the same vector (the shorter way round).
    for (double angle : {1e-14, 1e-6, 0.3, 2.0, 3.14159}) {
        const glm::dvec3 axis = glm::normalize(glm::dvec3(0.2, -1.0, 0.4));
        const glm::dquat q = glm::angleAxis(angle, axis);
        const glm::dvec3 w = rotationVector(q);
        EXPECT_NEAR(glm::length(w), angle, 1e-12 + 1e-9 * angle) << angle;
        EXPECT_NEAR(glm::length(rotationVector(-q) - w), 0.0, 1e-12) << angle;
        EXPECT_NEAR(rotationAngleBetween(rotationFromVector(w), q), 0.0, 1e-7) << angle;
    }
    EXPECT_EQ(rotationVector(glm::dquat(1, 0, 0, 0)), glm::dvec3(0));
    // A rotation by more than pi comes back as the shorter rotation the other way.
    const glm::dvec3 w = rotationVector(glm::angleAxis(4.0, glm::dvec3(0, 0, 1)));
    EXPECT_NEAR(w.z, 4.0 - 2.0 * glm::pi<double>(), 1e-12);
}

TEST(Pose, NonFiniteDetected) {
    Pose p;
    p.translation.x = std::nan("");
    EXPECT_FALSE(p.isFinite());
    EXPECT_TRUE(Pose().isFinite());
}

}  // namespace
}  // namespace mirage
