// Differential rendering: L_r sees only the real world, L_rv everything; the composite adds the
// virtual objects' change to the camera image (Knecht et al. 2013, Eqs. 1-2).
#include <gtest/gtest.h>

#include "core/Error.h"
#include "render/raytrace/DifferentialRendering.h"
#include "tests/support/TestSupport.h"
#include "testscenes/RaytraceTestScenes.h"

namespace mirage::raytrace {
namespace {

using namespace mirage::raytrace::test;

// A real floor under a real spot light and a real environment, with virtual objects on it: an
// opaque box (shadow), a glass ball (caustic) and a virtual point light.
Scene mixedScene(const std::filesystem::path& dir, bool withVirtual) {
    Scene s;
    cv::Mat env(8, 16, CV_32FC3, cv::Scalar(0.2, 0.25, 0.3));
    env.rowRange(4, 8).setTo(cv::Scalar::all(0.02));
    setEnvironment(s, dir / "env.exr", env);
    addObject(s, "floor", floorPrimitive(4.0f), lambert(glm::vec3(0.6f)), glm::dmat4(1.0),
              Origin::Real);
    Light spot;
    spot.type = Light::Type::Spot;
    spot.intensity = 6.0f;
    spot.outerConeAngle = 0.8f;
    spot.innerConeAngle = 0.6f;
    addLight(
        s, "spot", spot,
        glm::inverse(glm::lookAt(glm::dvec3(0, 2, 0), glm::dvec3(0, 0, 0), glm::dvec3(0, 0, -1))),
        Origin::Real);
    if (withVirtual) {
        addObject(s, "box", boxPrimitive({-0.7f, 0, -0.2f}, {-0.3f, 0.4f, 0.2f}),
                  lambert(glm::vec3(0.8f, 0.2f, 0.2f)), glm::dmat4(1.0), Origin::Virtual);
        addObject(s, "ball", spherePrimitive(0.2f, 48, 24), glass(1.5f), translate({0.4, 0.5, 0}),
                  Origin::Virtual);
        Light lamp;
        lamp.type = Light::Type::Point;
        lamp.intensity = 0.5f;
        lamp.color = {0.2f, 0.4f, 1.0f};
        addLight(s, "lamp", lamp, translate({0, 0.3, 1.0}), Origin::Virtual);
    }
    return s;
}

RenderCamera camera(const Scene& s, int w, int h) {
    return cameraFromNode(s, "cam", w, h);
}

TEST(RaytraceDifferential, RealOnlyRenderIgnoresVirtualObjectsAndCompositeAddsTheirChange) {
    auto dir = mirage::test::outputDir("rt_differential");
    Scene mixed = mixedScene(dir, true), realOnly = mixedScene(dir, false);
    addCameraNode(mixed, "cam", {0, 1.6, 2.2}, {0, 0.1, 0}, 0.9f);
    addCameraNode(realOnly, "cam", {0, 1.6, 2.2}, {0, 0.1, 0}, 0.9f);
    const int W = 40, H = 30;
    RenderSettings st;
    st.samplesPerPixel = 24;
    st.threads = 2;
    st.photonsPerPass = 20000;
    auto images = renderDifferential(mixed, testDevice(), camera(mixed, W, H), st);
    // L_r is exactly the render of the real scene alone (same seed, same geometry).
    auto plain = render(RayTracingScene(realOnly, SceneSubset::All, testDevice()),
                        camera(realOnly, W, H), st);
    EXPECT_EQ(cv::norm(images.realOnly, plain.radiance, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::countNonZero(plain.virtualCoverage), 0);
    EXPECT_GT(cv::countNonZero(images.virtualCoverage), 20);

    // The virtual objects change the image: shadows, caustics, the virtual light.
    EXPECT_LT(mirage::test::psnr(images.realOnly, images.realAndVirtual, 1.0), 30.0);

    // Camera image = L_r (synthetic footage without sensor effects): the composite is L_rv.
    cv::Mat comp = compositeDifferential(images.realOnly, images);
    EXPECT_LT(cv::norm(comp, images.realAndVirtual, cv::NORM_INF), 1e-3);

    // A camera twice as bright as the model: real pixels scale the change with it
    // (alpha = CI / L_r), virtual pixels keep L_rv.
    cv::Mat bright = images.realOnly * 2.0;
    cv::Mat comp2 = compositeDifferential(bright, images);
    int checked = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            float m = images.virtualCoverage.at<float>(y, x);
            auto rv = images.realAndVirtual.at<cv::Vec3f>(y, x);
            auto r = images.realOnly.at<cv::Vec3f>(y, x);
            auto c = comp2.at<cv::Vec3f>(y, x);
            if (m == 0.0f && r[1] > 0.05f) {
                EXPECT_NEAR(c[1], 2.0f * rv[1], 0.02f * std::max(1.0f, rv[1]));
                ++checked;
            }
            if (m == 1.0f) {
                EXPECT_NEAR(c[1], rv[1], 1e-5f);
            }
        }
    EXPECT_GT(checked, 100);
}

TEST(RaytraceDifferential, RejectsMismatchedCameraImage) {
    DifferentialImages images;
    images.realOnly = cv::Mat::zeros(4, 4, CV_32FC3);
    images.realAndVirtual = cv::Mat::zeros(4, 4, CV_32FC3);
    images.virtualCoverage = cv::Mat::zeros(4, 4, CV_32F);
    EXPECT_THROW(compositeDifferential(cv::Mat::zeros(5, 4, CV_32FC3), images), Error);
    EXPECT_THROW(compositeDifferential(cv::Mat::zeros(4, 4, CV_8UC3), images), Error);
}

TEST(RaytraceDifferential, MissingCameraNodeListsTheOnesThereAre) {
    Scene s;
    addCameraNode(s, "main", {0, 1, 1}, {0, 0, 0}, 0.8f);
    addCameraNode(s, "side", {1, 1, 0}, {0, 0, 0}, 0.8f);
    try {
        cameraFromNode(s, "nope", 8, 8);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        std::string what = e.what();
        EXPECT_NE(what.find("'nope'"), std::string::npos) << what;
        EXPECT_NE(what.find("'main'"), std::string::npos) << what;
        EXPECT_NE(what.find("'side'"), std::string::npos) << what;
    }
    // And a found camera follows the glTF node: it looks at the target along its +Z (OpenCV).
    auto cam = cameraFromNode(s, "main", 8, 8);
    glm::dvec3 forward = cam.T_world_camera.rotationMatrix() * glm::dvec3(0, 0, 1);
    EXPECT_NEAR(glm::dot(forward, glm::normalize(glm::dvec3(0, -1, -1))), 1.0, 1e-9);
    glm::dvec3 down = cam.T_world_camera.rotationMatrix() * glm::dvec3(0, 1, 0);
    EXPECT_LT(down.y, 0.0);  // image +Y is world-down-ish
}

}  // namespace
}  // namespace mirage::raytrace
