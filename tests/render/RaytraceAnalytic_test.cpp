// Analytic tests of the reference renderer (pbrt style): set-ups whose exact answer is known.
#include <gtest/gtest.h>

#include "render/raytrace/Bsdf.h"
#include "render/raytrace/ReferenceRenderer.h"
#include "tests/support/TestSupport.h"
#include "testscenes/RaytraceTestScenes.h"

namespace mirage::raytrace {
namespace {

using namespace mirage::raytrace::test;

RenderSettings quick(int spp, uint64_t seed = 7) {
    RenderSettings s;
    s.samplesPerPixel = spp;
    s.seed = seed;
    s.threads = 2;
    return s;
}

// Inside a closed Lambertian sphere (albedo 0.5) emitting 0.5: L = Le / (1 - albedo) = 1.
TEST(RaytraceAnalytic, WhiteFurnaceInsideEmittingSphere) {
    Scene s;
    addObject(s, "sphere", spherePrimitive(1.0f, 48, 24), lambert(glm::vec3(0.5f), glm::vec3(0.5f)),
              glm::dmat4(1.0));
    RayTracingScene rt(s, SceneSubset::All, testDevice());
    auto cam = lookAtCamera(16, 16, 8.0, {0, 0, 0}, {0, 0, -1});
    auto r = render(rt, cam, quick(64));
    EXPECT_NEAR(meanValue(r.radiance), 1.0, 0.02);
    EXPECT_LT(mirage::test::percentileAbsDiff(r.radiance, constantImage(16, 16, 1.0f), 0.9), 0.25);
    EXPECT_EQ(r.nonFiniteSamples, 0);
}

// A Lambertian sphere of albedo 1 in a uniform environment of radiance 1 is invisible.
TEST(RaytraceAnalytic, WhiteFurnaceAlbedoOneInUniformEnvironment) {
    Scene s;
    auto dir = mirage::test::outputDir("rt_furnace_env");
    setEnvironment(s, dir / "env.exr", constantImage(16, 8, 1.0f));
    addObject(s, "sphere", spherePrimitive(0.5f, 48, 24), lambert(glm::vec3(1.0f)),
              glm::dmat4(1.0));
    RayTracingScene rt(s, SceneSubset::All, testDevice());
    auto cam = lookAtCamera(16, 16, 14.0, {0, 0, 2}, {0, 0, 0});
    auto r = render(rt, cam, quick(32));
    EXPECT_NEAR(meanValue(r.radiance), 1.0, 0.01);
    double lo, hi;
    cv::minMaxLoc(r.radiance.reshape(1), &lo, &hi);
    EXPECT_GT(lo, 0.8);
    EXPECT_LT(hi, 1.2);
    // The comparison can fail: albedo 0.8 must give a visibly darker sphere.
    Scene dark = s;
    dark.materials[0].baseColor = glm::vec4(0.8f);
    RayTracingScene rtDark(dark, SceneSubset::All, testDevice());
    cv::Mat darkImage = render(rtDark, cam, quick(32)).radiance;
    EXPECT_LT(meanValue(darkImage(cv::Rect(6, 6, 4, 4))), 0.9);
    EXPECT_NEAR(meanValue(r.radiance(cv::Rect(6, 6, 4, 4))), 1.0, 0.03);
}

// Glass slab at normal incidence in front of an emitter of radiance 1: transmits (1-F)^2 per
// pass, (1-F)/(1+F) with all internal reflections; with absorption a per crossing,
// (1-F)^2 a / (1 - F^2 a^2).
TEST(RaytraceAnalytic, GlassSlabNormalIncidenceTransmitsFresnel) {
    const float ior = 1.5f;
    const double F = std::pow((ior - 1.0) / (ior + 1.0), 2.0);
    EXPECT_NEAR(fresnelDielectric(1.0f, ior), F, 1e-6);
    for (double a : {1.0, 0.5}) {
        Scene s;
        Material g = glass(ior);
        const float thickness = 0.1f;
        if (a < 1.0) {
            g.attenuationColor = glm::vec3(float(a));
            g.attenuationDistance = thickness;
        }
        addObject(s, "slab", boxPrimitive({-1, -1, -thickness}, {1, 1, 0}), g, glm::dmat4(1.0));
        addObject(s, "emitter", boxPrimitive({-3, -3, -2.1f}, {3, 3, -2}),
                  lambert(glm::vec3(0.0f), glm::vec3(1.0f)), glm::dmat4(1.0));
        RayTracingScene rt(s, SceneSubset::All, testDevice());
        auto cam = lookAtCamera(16, 16, 2000.0, {0, 0, 1}, {0, 0, -1});
        auto r = render(rt, cam, quick(256));
        double single = (1 - F) * (1 - F) * a;
        double all = single / (1 - F * F * a * a);
        EXPECT_NEAR(meanValue(r.radiance), all, 0.004) << "a=" << a;
        EXPECT_NEAR(meanValue(r.radiance), single, 0.006) << "a=" << a;
    }
}

// A perfect mirror shows the environment exactly: pixels whose whole footprint reflects into one
// environment texel equal that texel.
TEST(RaytraceAnalytic, MirrorReturnsEnvironmentExactly) {
    Scene s;
    auto dir = mirage::test::outputDir("rt_mirror");
    cv::Mat env(4, 8, CV_32FC3);
    for (int y = 0; y < env.rows; ++y)
        for (int x = 0; x < env.cols; ++x)
            env.at<cv::Vec3f>(y, x) = {0.1f + 0.1f * float(x), 0.2f * float(y + 1), 0.5f};
    setEnvironment(s, dir / "env.exr", env);
    // Mirror plane y = 0 facing up; camera looks down at 45 degrees.
    addObject(s, "mirror", floorPrimitive(20.0f), mirrorMaterial(), glm::dmat4(1.0));
    RayTracingScene rt(s, SceneSubset::All, testDevice());
    EnvironmentLight envLight(env, 1.0f, 0.0);
    auto cam = lookAtCamera(24, 24, 20.0, {0, 1, 0}, {0.3, 0, -1});
    auto r = render(rt, cam, quick(8));
    int checked = 0;
    const glm::mat3 R(cam.T_world_camera.rotationMatrix());
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 24; ++x) {
            // Texel seen through the pixel's corners.
            glm::ivec2 texel(-1);
            bool uniform = true, hitsMirror = true;
            for (double dy : {-0.5, 0.5})
                for (double dx : {-0.5, 0.5}) {
                    glm::vec3 d =
                        glm::normalize(R * glm::vec3(*cam.intrinsics.unproject({x + dx, y + dy})));
                    if (d.y >= 0) hitsMirror = false;
                    glm::vec3 refl{d.x, -d.y, d.z};
                    glm::vec2 uv = envLight.directionToUv(refl);
                    glm::ivec2 t(int(uv.x * 8), int(uv.y * 4));
                    if (texel.x >= 0 && t != texel) uniform = false;
                    texel = t;
                }
            if (!uniform || !hitsMirror) continue;
            ++checked;
            auto expect = env.at<cv::Vec3f>(texel.y, texel.x);
            auto got = r.radiance.at<cv::Vec3f>(y, x);
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], expect[k], 1e-5) << x << "," << y;
        }
    EXPECT_GT(checked, 100);
}

// With only a uniform environment of radiance 1 and passive materials (albedo <= 1), no pixel
// can be brighter than 1 on average: energy never grows. Random scenes of every material kind.
TEST(RaytraceAnalytic, EnergyNeverGrowsInRandomScenes) {
    auto dir = mirage::test::outputDir("rt_energy");
    for (int trial = 0; trial < 4; ++trial) {
        Rng rng(1234, uint64_t(trial));
        Scene s;
        setEnvironment(s, dir / "env.exr", constantImage(8, 4, 1.0f));
        for (int i = 0; i < 5; ++i) {
            Material m;
            m.baseColor = glm::vec4(rng.uniform(), rng.uniform(), rng.uniform(), 1.0f);
            m.metallic = rng.uniform() < 0.3f ? 1.0f : rng.uniform() * 0.5f;
            m.roughness = rng.uniform() < 0.3f ? 0.0f : rng.uniform();
            m.ior = 1.0f + 1.4f * rng.uniform();
            m.transmission = rng.uniform() < 0.4f ? 1.0f : 0.0f;
            glm::dvec3 c(rng.uniform() * 2 - 1, rng.uniform() * 2 - 1, rng.uniform() * 2 - 1);
            if (i % 2)
                addObject(s, "s" + std::to_string(i),
                          spherePrimitive(0.2f + 0.4f * rng.uniform(), 32, 16), m, translate(c));
            else
                addObject(s, "b" + std::to_string(i),
                          boxPrimitive(glm::vec3(-0.4f), glm::vec3(0.3f)), m, translate(c));
        }
        RayTracingScene rt(s, SceneSubset::All, testDevice());
        auto cam = lookAtCamera(24, 24, 16.0, {0, 0.5, 4}, {0, 0, 0});
        auto r = render(rt, cam, quick(24, uint64_t(trial + 1)));
        EXPECT_TRUE(allFinite(r.radiance));
        EXPECT_EQ(r.nonFiniteSamples, 0);
        EXPECT_LE(meanValue(r.radiance), 1.005) << "trial " << trial;
        double lo, hi;
        cv::minMaxLoc(r.radiance.reshape(1), &lo, &hi);
        EXPECT_GE(lo, 0.0);
    }
}

// An object of IOR 1.0, smooth and clear, bends nothing and reflects nothing: it vanishes.
TEST(RaytraceAnalytic, IorOneObjectVanishes) {
    auto dir = mirage::test::outputDir("rt_ior1");
    // Bright sky over a dark ground: a refracting sphere shows it upside down.
    cv::Mat env(8, 16, CV_32FC3, cv::Scalar::all(0.05));
    env.rowRange(0, 4).setTo(cv::Scalar(2.0, 1.8, 1.5));
    Scene base;
    setEnvironment(base, dir / "env.exr", env);
    addObject(base, "floor", floorPrimitive(4.0f), lambert(glm::vec3(0.6f)),
              translate({0, -0.5, 0}));
    Scene with = base;
    addObject(with, "ghost", spherePrimitive(0.4f, 32, 16), glass(1.0f), glm::dmat4(1.0),
              Origin::Virtual);
    auto cam = lookAtCamera(24, 24, 12.0, {0, 0.3, 2}, {0, 0, 0});
    auto a = render(RayTracingScene(base, SceneSubset::All, testDevice()), cam, quick(64));
    auto b = render(RayTracingScene(with, SceneSubset::All, testDevice()), cam, quick(64));
    double same = mirage::test::psnr(a.radiance, b.radiance, 2.0);
    EXPECT_GT(same, 30.0);
    // And IOR 1.5 does not vanish (the comparison can fail).
    with.materials.back().ior = 1.5f;
    auto c = render(RayTracingScene(with, SceneSubset::All, testDevice()), cam, quick(64));
    EXPECT_LT(mirage::test::psnr(a.radiance, c.radiance, 2.0), same - 10.0);
}

// Beyond the critical angle light inside glass is totally reflected; grazing and IOR 1 are exact.
TEST(RaytraceAnalytic, DielectricHardCases) {
    const float ior = 1.5f;
    float critical = std::asin(1.0f / ior);
    // From inside (cos < 0 convention: arriving from the inside), beyond the critical angle.
    EXPECT_FLOAT_EQ(fresnelDielectric(-std::cos(critical + 0.05f), ior), 1.0f);
    EXPECT_LT(fresnelDielectric(-std::cos(critical - 0.05f), ior), 1.0f);
    EXPECT_NEAR(fresnelDielectric(0.0f, ior), 1.0f, 1e-6);  // grazing
    EXPECT_FLOAT_EQ(fresnelDielectric(0.7f, 1.0f), 0.0f);   // IOR 1: no reflection
    for (float roughness : {0.0f, 0.3f}) {
        Bsdf bsdf(BsdfParams{glm::vec3(1.0f), 0.0f, roughness, ior, 1.0f, false});
        Rng rng(3, 4);
        int transmitted = 0;
        for (int i = 0; i < 2000; ++i) {
            float th = critical + 0.2f;  // inside the glass, beyond the critical angle
            glm::vec3 wo{std::sin(th), 0.0f, -std::cos(th)};
            Bsdf::Sample s;
            if (!bsdf.sample(wo, rng.uniform(), rng.uniform2(), TransportMode::Radiance, s))
                continue;
            EXPECT_TRUE(isFiniteVec(s.weight));
            if (s.transmitted) ++transmitted;
            if (roughness == 0.0f) {
                EXPECT_FALSE(s.transmitted);
                EXPECT_NEAR(s.weight.x, 1.0f, 1e-6);
            }
            // Grazing directions never produce NaN.
            glm::vec3 graze{1.0f, 0.0f, 1e-8f};
            if (bsdf.sample(graze, rng.uniform(), rng.uniform2(), TransportMode::Radiance, s)) {
                EXPECT_TRUE(isFiniteVec(s.weight));
            }
            EXPECT_TRUE(isFiniteVec(bsdf.eval(graze, glm::normalize(glm::vec3(-1, 0.1f, 0.01f)),
                                              TransportMode::Radiance)));
        }
        if (roughness == 0.0f) {
            EXPECT_EQ(transmitted, 0);
        } else {
            // Rough glass: microfacets tilted towards the ray let a little through; most reflects.
            EXPECT_LT(transmitted, 1000);
        }
    }
}

// Rays that leave a scene without an environment carry nothing; grazing views stay finite.
TEST(RaytraceAnalytic, RaysLeavingTheSceneAndGrazingViews) {
    Scene s;
    addObject(s, "floor", floorPrimitive(2.0f), lambert(glm::vec3(0.7f)), glm::dmat4(1.0));
    Light sun;
    sun.type = Light::Type::Directional;
    sun.intensity = 3.0f;
    addLight(
        s, "sun", sun,
        glm::inverse(glm::lookAt(glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 0), glm::dvec3(0, 0, -1))));
    RayTracingScene rt(s, SceneSubset::All, testDevice());
    // Camera at floor height looking along it: half the rays leave, the rest graze the floor.
    auto cam = lookAtCamera(16, 16, 12.0, {0, 1e-3, 1.5}, {0, 1e-3, 0});
    auto r = render(rt, cam, quick(8));
    EXPECT_TRUE(allFinite(r.radiance));
    EXPECT_EQ(r.nonFiniteSamples, 0);
    // Lambert under a 3 W/m^2 overhead sun: L = 0.7 * 3 / pi; nothing can exceed that.
    double lo, hi;
    cv::minMaxLoc(r.radiance.reshape(1), &lo, &hi);
    EXPECT_LE(hi, 0.7 * 3 / M_PI + 1e-3);
    // Sky pixels (top row) are black.
    EXPECT_EQ(cv::norm(r.radiance.row(0), cv::NORM_INF), 0.0);
    // An empty scene renders black.
    Scene empty;
    auto e = render(RayTracingScene(empty, SceneSubset::All, testDevice()), cam, quick(2));
    EXPECT_EQ(cv::norm(e.radiance, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace mirage::raytrace
