// Participating media inside translucent objects in the reference renderer: analytic set-ups
// (Beer-Lambert through a slab, homogeneous and with a density gradient, seen directly and as a
// shadow) and energy conservation of a white, non-absorbing medium in a uniform environment.
#include <gtest/gtest.h>

#include "render/raytrace/Bsdf.h"
#include "render/raytrace/ReferenceRenderer.h"
#include "tests/support/TestSupport.h"
#include "testscenes/TranslucentTestScenes.h"

namespace mirage::raytrace {
namespace {

using namespace mirage::raytrace::test;

RenderSettings quick(int spp, MediumScattering mode = MediumScattering::Multiple) {
    RenderSettings s;
    s.samplesPerPixel = spp;
    s.seed = 11;
    s.threads = 2;
    s.mediumScattering = mode;
    return s;
}

// A purely absorbing slab (albedo 0, 0.1 m thick) in front of an emitter of radiance 1, seen at
// normal incidence: e^{-sigma_t d}; with an IOR 1.5 boundary (Fresnel, no bending) and all
// internal reflections (1-F)^2 a / (1 - F^2 a^2), a = e^{-sigma_t d}; with a density rising
// linearly through the slab (two samples, 0.2 and 1.0), e^{-sigma_t d 0.6}.
TEST(RaytraceMedia, SlabTransmittanceIsBeerLambert) {
    const float d = 0.1f, sigma = 10.0f;
    struct Case {
        float ior;
        bool gradient;
        double expected;
    };
    const double a = std::exp(-double(sigma) * d);
    const double F = std::pow(0.5 / 2.5, 2.0);
    const std::vector<Case> cases = {
        {1.0f, false, a},
        {1.5f, false, (1 - F) * (1 - F) * a / (1 - F * F * a * a)},
        {1.0f, true, std::exp(-double(sigma) * d * 0.6)},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(testing::Message() << "ior " << c.ior << " gradient " << c.gradient);
        std::shared_ptr<const DensityGrid> grid;
        if (c.gradient)
            grid = makeDensityGrid(1, 1, 2, {-1, -1, -d}, {1, 1, 0},
                                   [&](glm::vec3 p) { return p.z < -0.5f * d ? 0.2f : 1.0f; });
        Scene s;
        addObject(s, "slab", boxPrimitive({-1, -1, -d}, {1, 1, 0}),
                  translucentMaterial(sigma, glm::vec3(0.0f), c.ior, grid), glm::dmat4(1.0));
        addObject(s, "emitter", boxPrimitive({-3, -3, -2.1f}, {3, 3, -2}),
                  lambert(glm::vec3(0.0f), glm::vec3(1.0f)), glm::dmat4(1.0));
        RayTracingScene rt(s, SceneSubset::All, testDevice());
        auto cam = lookAtCamera(16, 16, 2000.0, {0, 0, 1}, {0, 0, -1});
        auto r = render(rt, cam, quick(96));
        EXPECT_EQ(r.nonFiniteSamples, 0);
        EXPECT_NEAR(meanValue(r.radiance), c.expected, 0.01);
    }
    // The comparison can fail: a slab twice as thick is far darker than e^{-sigma_t d}.
    Scene s;
    addObject(s, "slab", boxPrimitive({-1, -1, -2 * d}, {1, 1, 0}),
              translucentMaterial(sigma, glm::vec3(0.0f)), glm::dmat4(1.0));
    addObject(s, "emitter", boxPrimitive({-3, -3, -2.1f}, {3, 3, -2}),
              lambert(glm::vec3(0.0f), glm::vec3(1.0f)), glm::dmat4(1.0));
    RayTracingScene rt(s, SceneSubset::All, testDevice());
    auto r = render(rt, lookAtCamera(16, 16, 2000.0, {0, 0, 1}, {0, 0, -1}), quick(32));
    EXPECT_LT(meanValue(r.radiance), a - 0.15);
}

// Shadow rays through a medium (ratio tracking through a density grid): a Lambertian floor under
// a directional light, half of it in the shadow of an absorbing slab whose density varies along
// the light's path. The camera sees the floor from below the slab, so shaded / lit = the slab's
// transmittance along the light.
TEST(RaytraceMedia, ShadowThroughAMediumIsItsTransmittance) {
    const float sigma = 8.0f, d = 0.1f;
    auto grid = makeDensityGrid(1, 4, 1, {-2, 0.5f, -2}, {0, 0.5f + d, 2},
                                [](glm::vec3 p) { return p.y < 0.55f ? 0.5f : 1.5f; });
    // Four samples along y: 0.5, 0.5, 1.5, 1.5 at centres; the integral over the slab is
    // d * (0.5 * 0.375 + 1.0 * 0.25 + 1.5 * 0.375) = d.
    Scene s;
    addObject(s, "slab", boxPrimitive({-2, 0.5f, -2}, {0, 0.5f + d, 2}),
              translucentMaterial(sigma, glm::vec3(0.0f), 1.0f, grid), glm::dmat4(1.0));
    addObject(s, "floor", floorPrimitive(4.0f), lambert(glm::vec3(0.5f)), glm::dmat4(1.0));
    Light sun;
    sun.type = Light::Type::Directional;
    sun.intensity = 3.0f;
    addLight(s, "sun", sun, glm::rotate(glm::dmat4(1.0), -kPi / 2.0, glm::dvec3(1, 0, 0)));
    RayTracingScene rt(s, SceneSubset::All, testDevice());
    auto cam = lookAtCamera(32, 16, 40.0, {0, 0.3, 1.2}, {0, 0, 0});
    auto r = render(rt, cam, quick(64));
    const double shaded = meanValue(r.radiance(cv::Rect(2, 10, 10, 5)));
    const double lit = meanValue(r.radiance(cv::Rect(20, 10, 10, 5)));
    EXPECT_NEAR(lit, 0.5 / kPi * 3.0, 0.01);
    EXPECT_NEAR(shaded / lit, std::exp(-double(sigma) * d), 0.02);
}

// A white (albedo 1), optically thick medium in a uniform environment of radiance 1 is invisible
// whatever its boundary's Fresnel and its density: every path leaves again. Albedo 0.8 darkens
// it, and single scattering alone loses what scatters more than once.
TEST(RaytraceMedia, WhiteMediumConservesEnergy) {
    auto dir = mirage::test::outputDir("rt_media_furnace");
    auto scene = [&](glm::vec3 albedo, float ior, bool gradient) {
        Scene s;
        setEnvironment(s, dir / "env.exr", constantImage(16, 8, 1.0f));
        std::shared_ptr<const DensityGrid> grid;
        if (gradient)
            grid = makeDensityGrid(4, 4, 4, glm::vec3(-0.3f), glm::vec3(0.3f),
                                   [](glm::vec3 p) { return 0.5f + 2.0f * (p.x + 0.3f); });
        addObject(s, "cube", boxPrimitive(glm::vec3(-0.3f), glm::vec3(0.3f)),
                  translucentMaterial(20.0f, albedo, ior, grid), glm::dmat4(1.0));
        return s;
    };
    auto cam = lookAtCamera(16, 16, 30.0, {0.4, 0.5, 1.6}, {0, 0, 0});
    for (auto [ior, gradient] : {std::pair{1.0f, false}, std::pair{1.5f, true}}) {
        SCOPED_TRACE(testing::Message() << "ior " << ior << " gradient " << gradient);
        RayTracingScene rt(scene(glm::vec3(1.0f), ior, gradient), SceneSubset::All, testDevice());
        auto r = render(rt, cam, quick(48));
        EXPECT_EQ(r.nonFiniteSamples, 0);
        EXPECT_NEAR(meanValue(r.radiance), 1.0, 0.015);
        EXPECT_LT(mirage::test::percentileAbsDiff(r.radiance, constantImage(16, 16, 1.0f), 0.5),
                  0.1);
    }
    RayTracingScene grey(scene(glm::vec3(0.8f), 1.0f, false), SceneSubset::All, testDevice());
    EXPECT_LT(meanValue(render(grey, cam, quick(16)).radiance(cv::Rect(5, 5, 6, 6))), 0.85);
    RayTracingScene white(scene(glm::vec3(1.0f), 1.0f, false), SceneSubset::All, testDevice());
    auto single = render(white, cam, quick(16, MediumScattering::Single));
    EXPECT_LT(meanValue(single.radiance(cv::Rect(5, 5, 6, 6))), 0.8);
}

}  // namespace
}  // namespace mirage::raytrace
