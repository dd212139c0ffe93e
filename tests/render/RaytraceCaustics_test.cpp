// Caustics and convergence of the reference renderer.
#include <gtest/gtest.h>

#include "render/raytrace/Bsdf.h"
#include "render/raytrace/ReferenceRenderer.h"
#include "tests/support/TestSupport.h"
#include "testscenes/RaytraceTestScenes.h"

namespace mirage::raytrace {
namespace {

using namespace mirage::raytrace::test;

// Flux (per unit incident irradiance) that a smooth glass sphere of radius R, lit by a parallel
// beam along +X, sends onto the plane x = planeX within radius rMax of the axis: every ray of
// impact parameter b is split by Fresnel at each interface (any number of internal reflections)
// and absorbed per unit length by sigma; exact geometry in the meridional plane.
double analyticCausticFlux(double R, double ior, double sigma, double planeX, double rMax) {
    const int n = 40000;
    double flux = 0.0;
    auto landing = [&](glm::dvec2 p, glm::dvec2 d, double w, double b) {
        if (d.x <= 1e-12) return 0.0;
        double t = (planeX - p.x) / d.x;
        double rho = std::abs(p.y + t * d.y);
        return rho < rMax ? w * 2.0 * M_PI * b : 0.0;
    };
    for (int i = 0; i < n; ++i) {
        double b = (i + 0.5) / n * R, db = R / n;
        glm::dvec2 p{-std::sqrt(R * R - b * b), b}, d{1, 0};
        glm::dvec2 nrm = p / R;  // outward
        double cosI = -glm::dot(d, nrm);
        double F = fresnelDielectric(float(cosI), float(ior));
        glm::dvec2 refl = d - 2.0 * glm::dot(d, nrm) * nrm;
        flux += landing(p, refl, F, b) * db;
        // Refract in.
        double eta = 1.0 / ior, cosT = std::sqrt(std::max(0.0, 1 - eta * eta * (1 - cosI * cosI)));
        glm::dvec2 dt = eta * d + (eta * cosI - cosT) * nrm;
        double w = 1 - F;
        for (int k = 0; k < 40 && w > 1e-9; ++k) {
            // Chord to the next interface.
            double tt = -2.0 * glm::dot(p, dt);
            glm::dvec2 q = p + tt * dt;
            w *= std::exp(-sigma * tt);
            glm::dvec2 nq = q / R;  // outward; the ray arrives from inside
            double ci = glm::dot(dt, nq);
            double Fi = fresnelDielectric(float(-ci), float(ior));
            // Exit.
            double e = ior, s2 = e * e * (1 - ci * ci);
            if (s2 < 1) {
                double ct = std::sqrt(1 - s2);
                glm::dvec2 out = e * dt + (ct - e * ci) * nq;
                flux += landing(q, glm::normalize(out), w * (1 - Fi), b) * db;
            }
            w *= Fi;
            dt = dt - 2.0 * ci * nq;
            p = q;
        }
    }
    return flux;
}

// Caustic energy: a parallel beam (directional light, 1 W/m^2 along +X) through a glass sphere
// onto a Lambertian wall at x = 1. The flux the renderer puts on the wall within 0.5 m of the
// axis (caustics on minus caustics off) must match the flux entering the sphere minus Fresnel
// and absorption losses, traced exactly.
TEST(RaytraceCaustics, GlassSphereCausticFluxMatchesFresnelAndAbsorption) {
    const double R = 0.1, ior = 1.5, rMax = 0.5, albedo = 0.5, planeX = 1.0;
    for (double absorbed : {0.0, 0.5}) {
        Scene s;
        Material g = glass(float(ior));
        double sigma = 0.0;
        if (absorbed > 0) {
            g.attenuationColor = glm::vec3(float(1 - absorbed));
            g.attenuationDistance = float(2 * R);  // half the light is lost along a diameter
            sigma = -std::log(1 - absorbed) / (2 * R);
        }
        addObject(s, "ball", spherePrimitive(float(R), 128, 64), g, glm::dmat4(1.0));
        addObject(s, "wall", boxPrimitive({float(planeX), -3, -3}, {float(planeX) + 0.1f, 3, 3}),
                  lambert(glm::vec3(float(albedo))), glm::dmat4(1.0));
        Light sun;
        sun.type = Light::Type::Directional;
        sun.intensity = 1.0f;
        // The light shines down its node's -Z: make -Z point along +X.
        addLight(
            s, "sun", sun,
            glm::inverse(glm::lookAt(glm::dvec3(0), glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0))));
        RayTracingScene rt(s, SceneSubset::All, testDevice());
        // Looks at the wall from x = 0.25 (never through the sphere at |x| < 0.1).
        const int W = 64, H = 64;
        auto cam = lookAtCamera(W, H, 33.0, {0.25, 0.0, 0.9}, {planeX, 0, 0});
        RenderSettings st;
        st.samplesPerPixel = 8;
        st.threads = 2;
        st.maxDepth = 1;  // the wall's first bounce only: no interreflection via the sphere
        st.photonsPerPass = 40000;
        st.initialPhotonRadius = 0.03f;
        auto on = render(rt, cam, st);
        st.caustics = false;
        auto off = render(rt, cam, st);
        EXPECT_GT(on.photonsStored, 100000);
        EXPECT_EQ(on.nonFiniteSamples, 0);
        double flux = 0.0, area = 0.0;
        const glm::dmat3 Rw = cam.T_world_camera.rotationMatrix();
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                glm::dvec3 dc = *cam.intrinsics.unproject({double(x), double(y)});
                glm::dvec3 d = Rw * dc;
                double t = (planeX - cam.T_world_camera.translation.x) / d.x;
                glm::dvec3 p = cam.T_world_camera.translation + t * d;
                if (std::hypot(p.y, p.z) >= rMax) continue;
                // Pixel footprint: solid angle (1/(fx fy)) cos^3(alpha) -> area t^2 / cos(theta).
                double cosAlpha = dc.z, solid = cosAlpha * cosAlpha * cosAlpha /
                                                (cam.intrinsics.fx * cam.intrinsics.fy);
                double A = solid * t * t / std::abs(d.x);
                area += A;
                auto a = on.radiance.at<cv::Vec3f>(y, x), b = off.radiance.at<cv::Vec3f>(y, x);
                flux += M_PI / albedo * (a[1] - b[1]) * A;
            }
        ASSERT_NEAR(area, M_PI * rMax * rMax, 0.02 * M_PI * rMax * rMax)
            << "the disk must be in view";
        double expected = analyticCausticFlux(R, ior, sigma, planeX, rMax);
        double incident = M_PI * R * R;
        EXPECT_NEAR(flux, expected, 0.05 * expected) << "absorbed " << absorbed;
        // Sanity of the reference itself: all light leaving forwards (an infinite wall) is the
        // incident flux minus Fresnel back-reflection (and absorption): a few percent (half).
        double forward = analyticCausticFlux(R, ior, sigma, planeX, 1e9);
        EXPECT_LT(forward, incident * (absorbed > 0 ? 0.7 : 0.99));
        EXPECT_GT(forward, incident * (absorbed > 0 ? 0.35 : 0.85));
        EXPECT_LT(expected, forward);
    }
}

// Error against a high-sample render falls as 1/sqrt(spp): slope of log(RMSE) over log(spp).
TEST(RaytraceConvergence, ErrorFallsAsInverseSquareRootOfSamples) {
    Scene s;
    auto dir = mirage::test::outputDir("rt_convergence");
    cv::Mat env(8, 16, CV_32FC3, cv::Scalar(0.3, 0.35, 0.5));
    env.rowRange(4, 8).setTo(cv::Scalar::all(0.05));
    setEnvironment(s, dir / "env.exr", env);
    addObject(s, "floor", floorPrimitive(4.0f), lambert(glm::vec3(0.7f)), glm::dmat4(1.0));
    Material metal;
    metal.baseColor = glm::vec4(0.9f, 0.6f, 0.3f, 1.0f);
    metal.metallic = 1.0f;
    metal.roughness = 0.4f;
    addObject(s, "box", boxPrimitive({-0.3f, 0, -0.3f}, {0.3f, 0.6f, 0.3f}), metal,
              glm::dmat4(1.0));
    Light spot;
    spot.type = Light::Type::Spot;
    spot.intensity = 8.0f;
    spot.outerConeAngle = 0.6f;
    spot.innerConeAngle = 0.4f;
    addLight(
        s, "spot", spot,
        glm::inverse(glm::lookAt(glm::dvec3(1, 2, 1), glm::dvec3(0, 0, 0), glm::dvec3(0, 1, 0))));
    RayTracingScene rt(s, SceneSubset::All, testDevice());
    auto cam = lookAtCamera(24, 24, 20.0, {0, 1.2, 2.2}, {0, 0.2, 0});
    RenderSettings st;
    st.threads = 2;
    st.samplesPerPixel = 1024;
    st.seed = 99;
    cv::Mat ref = render(rt, cam, st).radiance;
    std::vector<double> xs, ys;
    for (int spp : {4, 16, 64}) {
        // Mean squared error over independent seeds (a single image's error is itself noisy).
        double mse = 0.0;
        const int seeds = 4;
        for (int k = 0; k < seeds; ++k) {
            st.samplesPerPixel = spp;
            st.seed = 5 + uint64_t(k);
            cv::Mat img = render(rt, cam, st).radiance;
            double e = cv::norm(img, ref, cv::NORM_L2);
            mse += e * e / double(img.total() * 3) / seeds;
        }
        xs.push_back(std::log(double(spp)));
        ys.push_back(std::log(std::sqrt(mse)));
    }
    double mx = (xs[0] + xs[1] + xs[2]) / 3, my = (ys[0] + ys[1] + ys[2]) / 3, sxy = 0, sxx = 0;
    for (int i = 0; i < 3; ++i) {
        sxy += (xs[i] - mx) * (ys[i] - my);
        sxx += (xs[i] - mx) * (xs[i] - mx);
    }
    double slope = sxy / sxx;
    EXPECT_NEAR(slope, -0.5, 0.12)
        << "RMSE " << std::exp(ys[0]) << " " << std::exp(ys[1]) << " " << std::exp(ys[2]);
}

// Same seed -> the same image whatever the thread count; another seed -> another image.
TEST(RaytraceDeterminism, IndependentOfThreadCount) {
    Scene s;
    addObject(s, "floor", floorPrimitive(4.0f), lambert(glm::vec3(0.7f)), glm::dmat4(1.0));
    addObject(s, "ball", spherePrimitive(0.3f, 32, 16), glass(1.5f), translate({0, 0.5, 0}));
    Light point;
    point.type = Light::Type::Point;
    point.intensity = 5.0f;
    addLight(s, "lamp", point, translate({0.2, 1.5, 0.1}));
    RayTracingScene rt(s, SceneSubset::All, testDevice());
    auto cam = lookAtCamera(20, 20, 16.0, {0, 1.5, 2}, {0, 0.2, 0});
    RenderSettings st;
    st.samplesPerPixel = 4;
    st.photonsPerPass = 5000;
    st.threads = 1;
    auto a = render(rt, cam, st);
    st.threads = 2;
    auto b = render(rt, cam, st);
    EXPECT_GT(a.photonsStored, 0);
    EXPECT_EQ(cv::norm(a.radiance, b.radiance, cv::NORM_INF), 0.0);
    st.seed = 2;
    auto c = render(rt, cam, st);
    EXPECT_GT(cv::norm(a.radiance, c.radiance, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace mirage::raytrace
