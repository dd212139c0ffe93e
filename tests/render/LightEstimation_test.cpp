// Light estimation (render/LightEstimation.h) on synthetic environments whose light is known: a
// disc of known direction, size and radiance over a smooth sky, for several seeds; and none when
// there is no light.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <opencv2/imgproc.hpp>

#include "render/LightEstimation.h"
#include "testscenes/EnvironmentViews.h"

namespace mirage::render {
namespace {

struct Sun {
    glm::dvec3 direction;           // unit, towards the light
    double radiusRad;               // angular radius
    glm::vec3 radiance;             // inside the disc (on top of the sky)
    glm::vec3 irradiance() const {  // at normal incidence: radiance x solid angle
        return radiance * float(2 * M_PI * (1 - std::cos(radiusRad)));
    }
};

// A smooth sky (brighter up, a colour gradient; max / median < 3) plus the discs; 3x3 samples
// per texel so the discs' rims are area-weighted.
cv::Mat skyWithSuns(const std::vector<Sun>& suns, int w, int h, double tilt) {
    cv::Mat m(h, w, CV_32FC3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            glm::vec3 sum(0.0f);
            for (int sy = 0; sy < 3; ++sy)
                for (int sx = 0; sx < 3; ++sx) {
                    const glm::dvec3 d =
                        test::equirectDirection(x + (sx + 0.5) / 3, y + (sy + 0.5) / 3, w, h);
                    const float up = float(std::max(d.y, 0.0));
                    glm::vec3 L(0.12f + 0.10f * up + 0.02f * float(std::sin(tilt + 3 * d.x)),
                                0.13f + 0.11f * up, 0.15f + 0.14f * up);
                    for (const Sun& s : suns)
                        if (glm::dot(d, s.direction) >= std::cos(s.radiusRad)) L += s.radiance;
                    sum += L;
                }
            sum /= 9.0f;
            m.at<cv::Vec3f>(y, x) = cv::Vec3f(sum.r, sum.g, sum.b);
        }
    return m;
}

double angleDeg(const glm::dvec3& a, const glm::dvec3& b) {
    return std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0)) * 180 /
           M_PI;
}

TEST(LightEstimation, FindsTheDominantLightWithinFiveDegreesAndAQuarterOfItsIntensity) {
    for (uint32_t seed = 1; seed <= 6; ++seed) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> U(0, 1);
        const double elevation = (15 + 60 * U(rng)) * M_PI / 180, azimuth = 2 * M_PI * U(rng);
        Sun s;
        s.direction = {std::cos(elevation) * std::sin(azimuth), std::sin(elevation),
                       -std::cos(elevation) * std::cos(azimuth)};
        s.radiusRad = (2.5 + 4 * U(rng)) * M_PI / 180;
        const float E = float(1 + 4 * U(rng));  // W/m^2
        const glm::vec3 colour(1.0f, float(0.8 + 0.2 * U(rng)), float(0.6 + 0.4 * U(rng)));
        s.radiance = colour * (E / float(2 * M_PI * (1 - std::cos(s.radiusRad))));
        const cv::Mat map = skyWithSuns({s}, 512, 256, 6 * U(rng));
        const std::vector<EstimatedLight> found = estimateLights(map);
        ASSERT_EQ(found.size(), 1u) << "seed " << seed;
        const EstimatedLight& l = found[0];
        const double err = angleDeg(glm::dvec3(l.direction), s.direction);
        const glm::vec3 truth = s.irradiance();
        std::printf("[ lights ] seed %u: direction error %.2f deg, intensity %.3f vs %.3f W/m^2\n",
                    seed, err, l.intensity(), std::max({truth.r, truth.g, truth.b}));
        EXPECT_LE(err, 5.0) << "seed " << seed;
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(l.irradiance[c], truth[c], 0.25 * truth[c]) << "seed " << seed;
    }
}

TEST(LightEstimation, NoLightInAUniformOrSmoothEnvironment) {
    EXPECT_TRUE(estimateLights(cv::Mat(64, 128, CV_32FC3, cv::Scalar::all(0.4))).empty());
    EXPECT_TRUE(estimateLights(skyWithSuns({}, 256, 128, 1.0)).empty());
    // The same smooth sky with a light is not empty (the check can fail).
    Sun s{glm::normalize(glm::dvec3(0.3, 0.8, -0.4)), 4 * M_PI / 180, glm::vec3(300.0f)};
    EXPECT_EQ(estimateLights(skyWithSuns({s}, 256, 128, 1.0)).size(), 1u);
}

TEST(LightEstimation, TwoLightsStrongestFirstAndUnseenTexelsIgnored) {
    const Sun a{glm::normalize(glm::dvec3(0.6, 0.7, 0.2)), 4 * M_PI / 180, glm::vec3(400.0f)};
    const Sun b{glm::normalize(glm::dvec3(-0.5, 0.5, -0.6)), 3 * M_PI / 180, glm::vec3(250.0f)};
    cv::Mat map = skyWithSuns({a, b}, 512, 256, 0.5);
    auto found = estimateLights(map);
    ASSERT_EQ(found.size(), 2u);
    EXPECT_LE(angleDeg(glm::dvec3(found[0].direction), a.direction), 5.0);
    EXPECT_LE(angleDeg(glm::dvec3(found[1].direction), b.direction), 5.0);
    // The same map with alpha 0 (filled, never seen) over the stronger light: only b is left.
    cv::Mat rgba;
    cv::cvtColor(map, rgba, cv::COLOR_RGB2RGBA);
    for (int y = 0; y < rgba.rows; ++y)
        for (int x = 0; x < rgba.cols; ++x) {
            const glm::dvec3 d = test::equirectDirection(x + 0.5, y + 0.5, rgba.cols, rgba.rows);
            rgba.at<cv::Vec4f>(y, x)[3] = glm::dot(d, a.direction) > std::cos(0.3) ? 0.0f : 1.0f;
        }
    found = estimateLights(rgba);
    ASSERT_EQ(found.size(), 1u);
    EXPECT_LE(angleDeg(glm::dvec3(found[0].direction), b.direction), 5.0);
}

}  // namespace
}  // namespace mirage::render
