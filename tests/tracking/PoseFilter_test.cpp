#include <gtest/gtest.h>

#include <random>

#include "tracking/PoseFilter.h"

namespace mirage::tracking {
namespace {

Pose noisy(const Pose& p, std::mt19937& rng, double sigmaM, double sigmaRad) {
    std::normal_distribution<double> n(0.0, 1.0);
    Pose q = p;
    q.translation += sigmaM * glm::dvec3(n(rng), n(rng), n(rng));
    const glm::dvec3 w = sigmaRad * glm::dvec3(n(rng), n(rng), n(rng));
    q.rotation = glm::normalize(glm::angleAxis(glm::length(w), glm::normalize(w)) * q.rotation);
    return q;
}

struct Spread {
    double transStd = 0, rotStdRad = 0;
};
Spread spread(const std::vector<Pose>& poses, const Pose& truth) {
    Spread s;
    for (const auto& p : poses) {
        s.transStd +=
            glm::dot(p.translation - truth.translation, p.translation - truth.translation);
        const double a = rotationAngleBetween(p.rotation, truth.rotation);
        s.rotStdRad += a * a;
    }
    s.transStd = std::sqrt(s.transStd / poses.size());
    s.rotStdRad = std::sqrt(s.rotStdRad / poses.size());
    return s;
}

TEST(PoseFilter, RemovesJitterAtRest) {
    std::mt19937 rng(7);
    Pose truth = Pose::fromRotationTranslation(
        glm::mat3_cast(glm::angleAxis(0.8, glm::normalize(glm::dvec3(1, 2, 0.5)))),
        {0.1, 0.4, 0.3});
    PoseFilter f;
    std::vector<Pose> raw, filtered;
    for (int i = 0; i < 300; ++i) {
        const Pose m = noisy(truth, rng, 0.0005, glm::radians(0.05));
        const Pose o = f.update(m, i / 30.0);
        if (i >= 30) {  // after 1 s of settling
            raw.push_back(m);
            filtered.push_back(o);
        }
    }
    const Spread a = spread(raw, truth), b = spread(filtered, truth);
    // At rest the cutoff stays near 0.5 Hz: noise amplitude down by a factor of 3 or more.
    EXPECT_LT(b.transStd, a.transStd / 3) << a.transStd << " -> " << b.transStd;
    EXPECT_LT(b.rotStdRad, a.rotStdRad / 3) << a.rotStdRad << " -> " << b.rotStdRad;
}

TEST(PoseFilter, BoundedLagInFastMotion) {
    std::mt19937 rng(3);
    PoseFilter f;
    double worstT = 0, worstR = 0;
    const double v = 0.5, omega = glm::radians(90.0);  // 0.5 m/s and 90 deg/s
    for (int i = 0; i < 60; ++i) {
        const double t = i / 30.0;
        Pose truth = Pose::fromRotationTranslation(
            glm::mat3_cast(glm::angleAxis(omega * t, glm::dvec3(0, 1, 0))), {v * t, 0.3, 0.2});
        const Pose o = f.update(noisy(truth, rng, 0.0005, glm::radians(0.05)), t);
        if (i >= 10) {
            worstT = std::max(worstT, glm::length(o.translation - truth.translation));
            worstR = std::max(worstR, rotationAngleBetween(o.rotation, truth.rotation));
        }
    }
    // One Euro's lag bound 1/(2 pi beta) with beta = 20: 8 mm and 0.46 deg, plus noise.
    EXPECT_LT(worstT, 0.011);
    EXPECT_LT(glm::degrees(worstR), 0.7);
    // Without the speed term (plain 1 Hz low-pass) the same motion lags far more: the bound is
    // the filter's doing.
    OneEuroOptions plain;
    plain.translationBeta = plain.rotationBeta = 0;
    PoseFilter g(plain);
    double lagPlain = 0;
    for (int i = 0; i < 60; ++i) {
        const double t = i / 30.0;
        const Pose truth = Pose::fromRotationTranslation(glm::dmat3(1.0), {v * t, 0.3, 0.2});
        lagPlain = glm::length(g.update(truth, t).translation - truth.translation);
    }
    EXPECT_GT(lagPlain, 0.05);
}

TEST(PoseFilter, ResetStartsFromTheMeasurement) {
    PoseFilter f;
    f.update(Pose(), 0.0);
    Pose far;
    far.translation = {1, 0, 0};
    f.reset();
    const Pose o = f.update(far, 0.033);
    EXPECT_NEAR(o.translation.x, 1.0, 1e-12);
    // Time going backwards also restarts (a new video or a seek).
    const Pose o2 = f.update(Pose(), 0.0);
    EXPECT_NEAR(o2.translation.x, 0.0, 1e-12);
}

}  // namespace
}  // namespace mirage::tracking
