#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <opencv2/imgcodecs.hpp>

#include "core/Error.h"
#include "core/image/ImageIO.h"
#include "tests/support/TestSupport.h"
#include "testscenes/TrackingViews.h"
#include "tracking/EnvironmentMap.h"

namespace mirage::tracking {
namespace {

using testing::renderFisheye;
using testing::trueEnvironment;

using testing::hemisphereFisheye;

TEST(EnvironmentMap, DirectionPixelRoundTripAndAxes) {
    const int W = 64, H = 32;
    // Centre column looks along -Z, a quarter right along +X, top row up.
    EXPECT_NEAR(glm::dot(EnvironmentMap::direction(32, 16, W, H), glm::dvec3(0, 0, -1)), 1.0, 1e-9);
    EXPECT_NEAR(glm::dot(EnvironmentMap::direction(48, 16, W, H), glm::dvec3(1, 0, 0)), 1.0, 1e-9);
    EXPECT_GT(EnvironmentMap::direction(10, 0.01, W, H).y, 0.999);
    const glm::dvec2 p = EnvironmentMap::pixel(EnvironmentMap::direction(12.3, 7.7, W, H), W, H);
    EXPECT_NEAR(p.x, 12.3, 1e-9);
    EXPECT_NEAR(p.y, 7.7, 1e-9);
}

struct Comparison {
    double meanAbs = 0, p99 = 0;
    int valid = 0, wronglyValid = 0, missed = 0;
};

Comparison compare(const EnvironmentMap& env, const Pose& T_world_camera) {
    Comparison c;
    std::vector<double> errs;
    const glm::dvec3 axis = T_world_camera.rotation * glm::dvec3(0, 0, 1);
    for (int y = 0; y < env.height(); ++y)
        for (int x = 0; x < env.width(); ++x) {
            const glm::dvec3 d =
                EnvironmentMap::direction(x + 0.5, y + 0.5, env.width(), env.height());
            const double offAxisDeg =
                glm::degrees(std::acos(std::clamp(glm::dot(d, axis), -1.0, 1.0)));
            const bool valid = env.validity().at<uint8_t>(y, x) != 0;
            if (!valid) {
                if (offAxisDeg < 80) ++c.missed;
                continue;
            }
            ++c.valid;
            if (offAxisDeg > 91) ++c.wronglyValid;  // beyond the fish-eye's field: invented
            const cv::Vec3f got = env.radiance().at<cv::Vec3f>(y, x);
            const glm::dvec3 want = trueEnvironment(d);
            for (int k = 0; k < 3; ++k) errs.push_back(std::abs(got[k] - want[k]));
        }
    if (errs.empty()) return c;
    double sum = 0;
    for (double e : errs) sum += e;
    c.meanAbs = sum / errs.size();
    std::sort(errs.begin(), errs.end());
    c.p99 = errs[size_t(0.99 * (errs.size() - 1))];
    return c;
}

TEST(EnvironmentMap, RecoversAKnownEnvironmentFromAFisheyeFrame) {
    const auto cam = hemisphereFisheye(700);
    // Fish-eye looking up and a bit sideways.
    const Pose T = testing::lookAt({0.1, 0.3, 0.0}, {0.3, 1.3, -0.2}, glm::dvec3(0, 0, -1));
    const cv::Mat frame = renderFisheye(cam, T);
    cv::imwrite((test::outputDir("envmap") / "fisheye.png").string(), frame);
    EnvironmentMap env(256);
    env.update(frame, cam, T);
    writeLinearRgb(test::outputDir("envmap_out") / "env.png", env.radiance());
    const Comparison c = compare(env, T);
    // About a hemisphere seen: ~half of the sphere's directions (equirect pixels are not equal
    // area, so only a loose check of the count), none beyond 91 degrees, none missed within 80.
    EXPECT_GT(c.valid, 256 * 128 / 4);
    EXPECT_EQ(c.wronglyValid, 0);
    EXPECT_EQ(c.missed, 0);
    EXPECT_LT(c.meanAbs, 0.006);
    EXPECT_LT(c.p99, 0.03);

    // The comparison catches a wrong pose (10 degrees off): the same frame misplaced.
    EnvironmentMap wrong(256);
    const Pose off = Pose::fromRotationTranslation(
        glm::mat3_cast(glm::angleAxis(glm::radians(10.0), glm::dvec3(0, 0, 1)) * T.rotation),
        T.translation);
    wrong.update(frame, cam, off);
    const Comparison w = compare(wrong, T);
    EXPECT_GT(w.meanAbs, 3 * c.meanAbs + 0.01);
}

TEST(EnvironmentMap, NeverSeenStaysInvalidAndUpdatesAccumulate) {
    const auto cam = hemisphereFisheye(300);
    EnvironmentMap env(128);
    EXPECT_EQ(env.validFraction(), 0.0);
    const Pose up = testing::lookAt({0, 0, 0}, {0, 1, 0}, glm::dvec3(0, 0, -1));
    env.update(renderFisheye(cam, up), cam, up);
    const double afterUp = env.validFraction();
    EXPECT_GT(afterUp, 0.3);
    EXPECT_LT(afterUp, 0.6);
    // Straight down was never seen.
    const glm::dvec2 down = EnvironmentMap::pixel({0, -1, 0}, 128, 64);
    EXPECT_EQ(env.validity().at<uint8_t>(int(down.y) - 1, 10), 0);
    const Pose downPose = testing::lookAt({0, 0, 0}, {0, -1, 0}, glm::dvec3(0, 0, -1));
    env.update(renderFisheye(cam, downPose), cam, downPose);
    EXPECT_GT(env.validFraction(), 0.95);
    EXPECT_THROW(env.update(cv::Mat(10, 10, CV_8UC3), cam, up), Error);
}

TEST(EnvironmentMap, DirectionsBeyondTheCalibrationsReachAreNotSampled) {
    const auto cam = hemisphereFisheye(300);
    const Pose up = testing::lookAt({0, 0, 0}, {0, 1, 0}, glm::dvec3(0, 0, -1));
    const cv::Mat frame = renderFisheye(cam, up);
    EnvironmentMap full(128), reached(128);
    full.update(frame, cam, up);
    reached.setReachDeg(50.0);
    reached.update(frame, cam, up);
    // Directions by their angle off the camera's axis (world +Y here): within 48 degrees both
    // maps sampled them alike; beyond 52 only the map without a reach did, the other left them
    // as unseen (invalid, radiance 0).
    int inside = 0, beyondFull = 0, beyondReached = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 128; ++x) {
            const glm::dvec3 d = EnvironmentMap::direction(x + 0.5, y + 0.5, 128, 64);
            const double offAxisDeg = glm::degrees(std::acos(std::clamp(d.y, -1.0, 1.0)));
            const bool vf = full.validity().at<uint8_t>(y, x) != 0;
            const bool vr = reached.validity().at<uint8_t>(y, x) != 0;
            if (offAxisDeg < 48) {
                EXPECT_TRUE(vr) << x << "," << y;
                inside += vr;
            } else if (offAxisDeg > 52) {
                beyondFull += vf && offAxisDeg < 85;
                beyondReached += vr;
                if (!vr) {
                    EXPECT_EQ(reached.radiance().at<cv::Vec3f>(y, x), cv::Vec3f(0, 0, 0));
                }
            }
        }
    EXPECT_GT(inside, 100);
    EXPECT_GT(beyondFull, 300);  // the frame does see there
    EXPECT_EQ(beyondReached, 0);
    EXPECT_LT(reached.validFraction(), 0.6 * full.validFraction());
    // No reach (a calibration without the field): the whole field, as before.
    reached.setReachDeg(-1);
    reached.update(frame, cam, up);
    EXPECT_NEAR(reached.validFraction(), full.validFraction(), 1e-12);
}

}  // namespace
}  // namespace mirage::tracking
