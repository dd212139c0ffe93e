// Constant-velocity pose prediction (tracking/PosePredictor.h): exact for the screw motions a
// constant twist describes (an orbit, a pan), much closer than the last pose for noisy
// measurements of a constant motion, and no velocity where it cannot be known.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "testscenes/NoisyPose.h"
#include "tracking/PosePredictor.h"

namespace mirage::tracking {
namespace {

// A camera orbiting the world's origin at `radius` metres, `height` above it, looking at the
// origin, `rate` radians per second: a constant twist in the camera's frame.
Pose orbit(double t, double rate, double radius = 0.5, double height = 0.3) {
    const double a = rate * t;
    return cameraLookingAt({radius * std::cos(a), height, radius * std::sin(a)}, {0, 0, 0},
                           {0, 1, 0});
}

// A camera moving along a straight line at a constant speed while it turns at a constant rate
// about the world's vertical (a pan while walking): not a screw motion in general.
Pose pan(double t) {
    const Pose base = cameraLookingAt({0.1, 0.35, 0.6}, {0, 0, 0}, {0, 1, 0});
    Pose p = base;
    p.rotation = glm::normalize(glm::angleAxis(0.4 * t, glm::dvec3(0, 1, 0)) * base.rotation);
    p.translation = base.translation + t * glm::dvec3(0.3, 0.0, -0.1);
    return p;
}

double translationError(const Pose& a, const Pose& b) {
    return glm::length(a.translation - b.translation);
}

double median(std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    return v[v.size() / 2];
}

TEST(PosePredictor, VelocityBetweenTwoPosesMovesTheFirstOntoTheSecond) {
    const Pose a = orbit(0.0, 1.3), b = orbit(0.25, 1.3);
    const PoseVelocity v = velocityBetween(a, b, 0.25);
    const Pose c = extrapolatePose(a, v, 0.25);
    EXPECT_LT(translationError(c, b), 1e-12);
    EXPECT_LT(rotationAngleBetween(c.rotation, b.rotation), 1e-12);
    // Backwards too, and a motion without rotation (the small-angle series).
    EXPECT_LT(translationError(extrapolatePose(b, v, -0.25), a), 1e-12);
    Pose d = a;
    d.translation += glm::dvec3(0.01, -0.02, 0.005);
    const Pose e = extrapolatePose(a, velocityBetween(a, d, 0.1), 0.2);
    EXPECT_LT(translationError(
                  e, Pose{a.rotation, a.translation + 2.0 * (d.translation - a.translation)}),
              1e-12);
}

// An orbit at a constant rate is a screw motion: predicted exactly 0.3 s ahead of the last
// pose, where the last pose itself is 0.15 m away.
TEST(PosePredictor, PredictsAnOrbitExactly) {
    PosePredictor p;
    p.update(orbit(0.0, 1.0), 0.0);
    EXPECT_FALSE(p.velocity()) << "one pose gave a velocity";
    p.update(orbit(0.1, 1.0), 0.1);
    ASSERT_TRUE(p.velocity());
    const Pose truth = orbit(0.4, 1.0);
    const Pose predicted = *p.predict(0.4);
    EXPECT_LT(translationError(predicted, truth), 1e-9);
    EXPECT_LT(rotationAngleBetween(predicted.rotation, truth.rotation), 1e-9);
    EXPECT_GT(translationError(orbit(0.1, 1.0), truth), 0.1);
}

// Noisy measurements (0.3 mm, 0.03 degree per axis: the estimator's noise on the sample) of a
// walking pan at 30 frames/s: predicted 150 ms ahead from every pair of consecutive poses, the
// pose at that time is much closer than the last measured pose (what rendering without
// prediction shows).
TEST(PosePredictor, PredictionBeatsTheLastPoseOnNoisyConstantMotion) {
    std::mt19937 rng(3);
    const double sigmaM = 0.0003, sigmaRad = glm::radians(0.03), ahead = 0.15;
    PosePredictor p;
    std::vector<double> predictedM, lastM, predictedDeg, lastDeg;
    for (int i = 0; i < 60; ++i) {
        const double t = i / 30.0;
        const Pose measured = test::noisyPose(pan(t), rng, sigmaM, sigmaRad);
        p.update(measured, t);
        if (!p.velocity()) continue;
        const Pose truth = pan(t + ahead);
        const Pose predicted = *p.predict(t + ahead);
        predictedM.push_back(translationError(predicted, truth));
        lastM.push_back(translationError(measured, truth));
        predictedDeg.push_back(
            glm::degrees(rotationAngleBetween(predicted.rotation, truth.rotation)));
        lastDeg.push_back(glm::degrees(rotationAngleBetween(measured.rotation, truth.rotation)));
    }
    ASSERT_EQ(predictedM.size(), 59u);
    std::printf("150 ms ahead: median %.2f mm, %.3f deg predicted; %.2f mm, %.3f deg last pose\n",
                1e3 * median(predictedM), median(predictedDeg), 1e3 * median(lastM),
                median(lastDeg));
    // The pan moves 47 mm and turns 3.4 degrees in 150 ms; noise over one frame's difference,
    // carried 4.5 frames ahead, leaves a few millimetres and tenths of a degree.
    EXPECT_LT(median(predictedM), 0.2 * median(lastM));
    EXPECT_LT(median(predictedDeg), 0.2 * median(lastDeg));
    EXPECT_LT(median(predictedM), 0.006);
}

// No velocity across a gap, a time that goes back, a non-finite pose or a reset; the horizon
// is cut to maxAheadS.
TEST(PosePredictor, NoVelocityWhereItCannotBeKnownAndABoundedHorizon) {
    PosePredictorOptions o;
    o.maxGapS = 0.5;
    o.maxAheadS = 0.2;
    PosePredictor p(o);
    EXPECT_FALSE(p.predict(1.0));
    p.update(orbit(0.0, 1.0), 0.0);
    // Without a velocity the last pose is the prediction.
    EXPECT_LT(translationError(*p.predict(0.3), orbit(0.0, 1.0)), 1e-15);
    p.update(orbit(0.6, 1.0), 0.6);
    EXPECT_FALSE(p.velocity()) << "a velocity across a 0.6 s gap";
    p.update(orbit(0.7, 1.0), 0.7);
    ASSERT_TRUE(p.velocity());
    EXPECT_DOUBLE_EQ(p.horizon(2.0), 0.2);
    EXPECT_DOUBLE_EQ(p.horizon(0.5), 0.0) << "a time before the last pose predicts backwards";
    EXPECT_LT(translationError(*p.predict(2.0), orbit(0.9, 1.0)), 1e-9);
    p.update(orbit(0.65, 1.0), 0.65);
    EXPECT_FALSE(p.velocity()) << "a velocity from a time that went back";
    p.update(orbit(0.75, 1.0), 0.75);
    ASSERT_TRUE(p.velocity());
    Pose bad = orbit(0.8, 1.0);
    bad.translation.x = std::nan("");
    p.update(bad, 0.8);
    EXPECT_FALSE(p.predict(0.9)) << "a non-finite pose was kept";
    p.update(orbit(0.85, 1.0), 0.85);
    p.update(orbit(0.9, 1.0), 0.9);
    ASSERT_TRUE(p.velocity());
    // A jump (the orbit half way round in 0.1 s: 10 m/s) gives no velocity.
    p.update(orbit(3.1, 1.0), 1.0);
    EXPECT_FALSE(p.velocity()) << "a jump gave a velocity";
    p.update(orbit(0.9, 1.0), 1.1);
    p.reset();
    EXPECT_FALSE(p.velocity());
    EXPECT_FALSE(p.predict(1.0));
}

}  // namespace
}  // namespace mirage::tracking
