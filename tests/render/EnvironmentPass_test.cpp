// The live environment (render/passes/environment, docs/environment.md): an environment-camera
// frame becomes the environment map, its SH9 and the diffuse light, only when a new frame arrives.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/camera/EquirectProjection.h"
#include "core/image/ImageIO.h"
#include "render/Renderer.h"
#include "render/passes/direct/DirectLightPass.h"
#include "render/raytrace/SyntheticFootage.h"
#include "tests/support/HeadlessGlSuite.h"
#include "tests/support/TestSupport.h"
#include "testscenes/EnvironmentViews.h"
#include "testscenes/RenderTestScenes.h"

namespace mirage::render {
namespace {

using test::addBox;
using test::addFloor;
using test::addMaterial;
using test::lookAtPose;
using test::smallCamera;

class EnvironmentPassTest : public test::HeadlessGlSuite {};

// The environment camera of `mirage synth`: looking straight up (camera +Z = world +Y, +X = world
// +X, image down = world -Z).
Pose upwardPose() {
    return Pose::fromRotationTranslation(glm::dmat3(1, 0, 0, 0, 0, -1, 0, 1, 0),
                                         glm::dvec3(0.0, 0.02, -0.4));
}

// A smooth environment with colour: brighter up, and towards +X / -Z.
glm::vec3 smoothSky(const glm::dvec3& d) {
    const float up = float(std::max(d.y, 0.0));
    return {float(0.30 + 0.15 * d.x + 0.30 * up), float(0.32 + 0.10 * d.x - 0.08 * d.z + 0.25 * up),
            float(0.35 - 0.12 * d.z + 0.35 * up)};
}

EnvironmentCameraSetup fixedCamera(const CameraIntrinsics& K, const Pose& T_world_camera) {
    EnvironmentCameraSetup s;
    s.intrinsics = K;
    s.T_world_camera = T_world_camera;
    return s;
}

Scene floorScene(float albedo) {
    Scene scene;
    const int m = addMaterial(scene, glm::vec3(albedo));
    addFloor(scene, "floor", 0.0f, 4.0f, m, Origin::Real);
    return scene;
}

struct MapError {
    double meanAbs = 0, p99 = 0;
    int seen = 0, seenBeyond = 0, missedWithin = 0;
};

// The map's seen texels against the true environment; `axis` = the camera's optical axis in the
// world (seen texels farther than 96 degrees from it, or unseen within 85, are counted).
MapError compareMap(const cv::Mat& map, const test::RadianceFn& truth, const glm::dvec3& axis) {
    MapError e;
    std::vector<double> errs;
    for (int y = 0; y < map.rows; ++y)
        for (int x = 0; x < map.cols; ++x) {
            const cv::Vec4f v = map.at<cv::Vec4f>(y, x);
            const glm::dvec3 d = test::equirectDirection(x + 0.5, y + 0.5, map.cols, map.rows);
            const double off = std::acos(std::clamp(glm::dot(d, axis), -1.0, 1.0)) * 180 / M_PI;
            if (v[3] < 0.5) {
                if (off < 85) ++e.missedWithin;
                continue;
            }
            ++e.seen;
            if (off > 96) ++e.seenBeyond;
            const glm::vec3 t = truth(d);
            for (int c = 0; c < 3; ++c) errs.push_back(std::abs(double(v[c]) - t[c]));
        }
    if (errs.empty()) return e;
    double sum = 0;
    for (double v : errs) sum += v;
    e.meanAbs = sum / double(errs.size());
    std::sort(errs.begin(), errs.end());
    e.p99 = errs[size_t(0.99 * double(errs.size() - 1))];
    return e;
}

TEST_F(EnvironmentPassTest, FisheyeFrameBecomesTheEnvironmentMap) {
    const CameraIntrinsics K = raytrace::equidistantFisheye(320, 190.0);
    const Pose T = upwardPose();
    const cv::Mat frame = test::renderEnvironmentView(K, T, smoothSky);
    RendererOptions o;
    o.environment.mapWidth = 128;
    Renderer r(floorScene(0.5f), smallCamera(), o);
    r.setEnvironmentCamera(fixedCamera(K, T));
    ASSERT_TRUE(r.updateEnvironment(frame, 0.0));
    const FrameReport& rep = r.render({lookAtPose({0, 2, 2}, {0, 0, 0}), {}, false});
    EXPECT_TRUE(rep.ran("environment"));
    const cv::Mat map = r.readEnvironmentMap();
    ASSERT_EQ(map.cols, 128);
    ASSERT_EQ(map.rows, 64);
    const MapError e = compareMap(map, smoothSky, {0, 1, 0});
    std::printf("[ env map ] seen %d texels, mean |err| %.4f, p99 %.4f\n", e.seen, e.meanAbs,
                e.p99);
    // 8-bit sRGB quantisation of values ~0.3 is ~0.002; bilinear over a smooth map adds little.
    EXPECT_LT(e.meanAbs, 0.006);
    EXPECT_LT(e.p99, 0.02);
    EXPECT_EQ(e.seenBeyond, 0);
    EXPECT_EQ(e.missedWithin, 0);
    // The unseen lower hemisphere is the mirror of the upper one (alpha 0).
    int filled = 0;
    double worst = 0;
    for (int y = map.rows / 2 + 4; y < map.rows; ++y)
        for (int x = 0; x < map.cols; ++x) {
            const cv::Vec4f v = map.at<cv::Vec4f>(y, x), m = map.at<cv::Vec4f>(map.rows - 1 - y, x);
            if (v[3] > 0.5) continue;
            ++filled;
            for (int c = 0; c < 3; ++c) worst = std::max(worst, double(std::abs(v[c] - m[c])));
        }
    EXPECT_GT(filled, map.cols * 20);
    EXPECT_LT(worst, 0.01);

    // The comparison catches a wrong extrinsic: the same frame with the pose turned 10 degrees.
    Renderer wrong(floorScene(0.5f), smallCamera(), o);
    const Pose tilted = Pose::fromRotationTranslation(
        glm::dmat3(glm::angleAxis(glm::radians(10.0), glm::dvec3(0, 0, 1))) * T.rotationMatrix(),
        T.translation);
    wrong.setEnvironmentCamera(fixedCamera(K, tilted));
    wrong.updateEnvironment(frame, 0.0);
    wrong.render({lookAtPose({0, 2, 2}, {0, 0, 0}), {}, false});
    const MapError bad = compareMap(wrong.readEnvironmentMap(), smoothSky,
                                    tilted.rotationMatrix() * glm::dvec3(0, 0, 1));
    std::printf("[ env map ] pose off by 10 deg: mean |err| %.4f\n", bad.meanAbs);
    EXPECT_GT(bad.meanAbs, 0.006);
}

// The fill of the unseen part, stated with its error: the bundled room environment (a bright
// window, dim walls, a darker floor) filmed by the upward environment camera; the map against the
// environment itself, over the seen texels and over the filled ones (the lower hemisphere, whose
// floor gets the mirrored walls and window).
TEST_F(EnvironmentPassTest, FillOfTheUnseenPartIsStatedWithItsError) {
    const cv::Mat room = readLinearRgb(test::dataDir() / "scenes" / "tabletop" / "env.pfm");
    const test::RadianceFn truth = [&](const glm::dvec3& d) {
        const glm::dvec2 p = equirectPixel(d, room.cols, room.rows);
        const int x = std::clamp(int(p.x), 0, room.cols - 1),
                  y = std::clamp(int(p.y), 0, room.rows - 1);
        const cv::Vec3f c = room.at<cv::Vec3f>(y, x);
        return glm::vec3(c[0], c[1], c[2]);
    };
    const CameraIntrinsics K = raytrace::equidistantFisheye(480, 190.0);
    const Pose T = upwardPose();
    RendererOptions o;
    o.environment.mapWidth = 256;
    Renderer r(floorScene(0.5f), smallCamera(), o);
    r.setEnvironmentCamera(fixedCamera(K, T));
    r.updateEnvironment(test::renderEnvironmentView(K, T, truth), 0.0);
    r.render({lookAtPose({0, 2, 2}, {0, 0, 0}), {}, false});
    const cv::Mat map = r.readEnvironmentMap();
    double seenErr = 0, fillErr = 0, seenN = 0, fillN = 0, truthMean = 0;
    for (int y = 0; y < map.rows; ++y)
        for (int x = 0; x < map.cols; ++x) {
            const cv::Vec4f v = map.at<cv::Vec4f>(y, x);
            const glm::vec3 t =
                truth(test::equirectDirection(x + 0.5, y + 0.5, map.cols, map.rows));
            double e = 0;
            for (int c = 0; c < 3; ++c) e += std::abs(double(v[c]) - t[c]) / 3;
            truthMean += (t.r + t.g + t.b) / 3;
            (v[3] > 0.5 ? seenErr : fillErr) += e;
            (v[3] > 0.5 ? seenN : fillN) += 1;
        }
    seenErr /= std::max(seenN, 1.0);
    fillErr /= std::max(fillN, 1.0);
    truthMean /= double(map.total());
    std::printf(
        "[ env fill ] room: mean radiance %.3f; mean |err| seen %.4f (%.0f texels), filled "
        "%.4f (%.0f texels)\n",
        truthMean, seenErr, seenN, fillErr, fillN);
    // Seen: 8-bit quantisation and the window's edges. Filled: the mirrored walls and window are
    // brighter than the real floor (0.05), which is why error figures mask the filled part.
    EXPECT_LT(seenErr, 0.02);
    EXPECT_GT(fillErr, 2 * seenErr);
    EXPECT_LT(fillErr, 0.5);
}

// The CPU resampling (core/camera/EquirectProjection.h: mirage track --envmap, both renderers'
// fish-eye scene environments) and the GPU pass give the same map, fill included.
TEST_F(EnvironmentPassTest, CpuAndGpuMappingsAgreeFillIncluded) {
    const CameraIntrinsics K = raytrace::equidistantFisheye(200, 190.0);
    const Pose T = upwardPose();
    const cv::Mat frame = test::renderEnvironmentView(K, T, smoothSky);
    RendererOptions o;
    o.environment.mapWidth = 128;
    Renderer r(floorScene(0.5f), smallCamera(), o);
    r.setEnvironmentCamera(fixedCamera(K, T));
    r.updateEnvironment(frame, 0.0);
    r.render({lookAtPose({0, 2, 2}, {0, 0, 0}), {}, false});
    const cv::Mat gpu = r.readEnvironmentMap();
    cv::Mat seen;
    const cv::Mat cpu = equirectFromCamera(srgbBgr8ToLinearRgb(frame), K, T, 128, 64, -1, &seen);
    double err = 0;
    int maskDiff = 0;
    for (int y = 0; y < cpu.rows; ++y)
        for (int x = 0; x < cpu.cols; ++x) {
            const cv::Vec4f g = gpu.at<cv::Vec4f>(y, x);
            const cv::Vec3f c = cpu.at<cv::Vec3f>(y, x);
            for (int k = 0; k < 3; ++k) err += std::abs(double(g[k]) - c[k]) / 3;
            maskDiff += (g[3] > 0.5) != (seen.at<uchar>(y, x) != 0);
        }
    err /= double(cpu.total());
    std::printf("[ env cpu/gpu ] mean |GPU - CPU| %.5f, mask differs at %d texels\n", err,
                maskDiff);
    EXPECT_LT(err, 0.002);   // half floats and the GPU's bilinear weights
    EXPECT_LE(maskDiff, 8);  // texels on the border of the seen part
}

TEST_F(EnvironmentPassTest, GpuShMatchesTheCpuProjectionOfTheSameMap) {
    const CameraIntrinsics K = raytrace::equidistantFisheye(256, 190.0);
    const Pose T = upwardPose();
    RendererOptions o;
    o.environment.mapWidth = 256;  // the SH9 reads mip level 1 (128 wide)
    Renderer r(floorScene(0.5f), smallCamera(), o);
    r.setEnvironmentCamera(fixedCamera(K, T));
    r.updateEnvironment(test::renderEnvironmentView(K, T, smoothSky), 0.0);
    r.render({lookAtPose({0, 2, 2}, {0, 0, 0}), {}, false});
    const cv::Mat map = r.readEnvironmentMap();
    cv::Mat rgb;
    cv::cvtColor(map, rgb, cv::COLOR_RGBA2RGB);
    const std::vector<glm::vec3> cpu = GpuScene::projectEquirectToSH(rgb, 1.0f, 0.0);
    const GpuEnvironment gpu = r.readEnvironmentLight();
    const float scale = glm::length(cpu[0]);
    for (int i = 0; i < 9; ++i)
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(gpu.envSH[i][c], cpu[size_t(i)][c], 0.01f * scale) << "coefficient " << i;
    // The fish-eye model is trusted to 90 degrees off its axis (CameraIntrinsics::maxFisheyeTheta),
    // though the lens sees 95: the upper hemisphere.
    EXPECT_NEAR(gpu.envSeenFraction, 0.5, 0.02);
    EXPECT_EQ(gpu.envRotation, 0.0f);
}

// Lambertian floor under a uniform environment: L = albedo x radiance; every new frame changes
// the light at the next render, and only a new frame runs the pass.
TEST_F(EnvironmentPassTest, DiffuseLightFollowsEachNewFrameAndOnlyThen) {
    const CameraIntrinsics K = raytrace::equidistantFisheye(96, 190.0);
    const Pose T = upwardPose();
    const CameraIntrinsics cam = smallCamera();
    Renderer r(floorScene(0.5f), cam);
    const Pose view = lookAtPose({0, 2.5, 2.5}, {0, 0, 0});
    auto floor = [&] {
        return r.readBuffer(kDirectRv).at<cv::Vec3f>(cam.height / 2, cam.width / 2)[0];
    };
    r.render({view, {}, false});
    EXPECT_FALSE(r.lastReport().reused("environment"));
    EXPECT_NEAR(floor(), 0.0, 1e-4);  // the scene has no environment
    r.render({view, {}, false});
    EXPECT_TRUE(r.lastReport().reused("environment"));

    r.setEnvironmentCamera(fixedCamera(K, T));
    const cv::Mat grey(K.height, K.width, CV_8UC3, cv::Scalar::all(128));
    ASSERT_TRUE(r.updateEnvironment(grey, 1.0));
    r.render({view, {}, false});
    EXPECT_TRUE(r.lastReport().ran("environment"));
    const float l128 = srgbToLinear(128.0f / 255.0f);
    // (1 - F) of the dielectric's Lambert part: within 5 %.
    EXPECT_NEAR(floor(), 0.5f * l128, 0.5f * l128 * 0.05f);
    r.render({view, {}, false});
    EXPECT_TRUE(r.lastReport().reused("environment"));
    EXPECT_FALSE(r.updateEnvironment(grey, 1.0));  // the same frame again

    const cv::Mat bright(K.height, K.width, CV_8UC3, cv::Scalar::all(200));
    ASSERT_TRUE(r.updateEnvironment(bright, 1.1));
    r.render({view, {}, false});
    EXPECT_TRUE(r.lastReport().ran("environment"));
    const float l200 = srgbToLinear(200.0f / 255.0f);
    EXPECT_NEAR(floor(), 0.5f * l200, 0.5f * l200 * 0.05f);

    r.setEnvironmentGain(glm::vec3(2.0f));
    r.render({view, {}, false});
    EXPECT_TRUE(r.lastReport().ran("environment"));
    EXPECT_NEAR(floor(), 1.0f * l200, l200 * 0.05f);

    r.useStaticEnvironment();
    r.render({view, {}, false});
    EXPECT_TRUE(r.lastReport().ran("environment"));
    EXPECT_NEAR(floor(), 0.0, 1e-4);
}

// A box under an environment that is bright on one side: the face towards the bright side is
// the brighter one, and when the environment turns, the lighting turns in the very next frame.
TEST_F(EnvironmentPassTest, LightingTurnsWithTheEnvironmentWithinOneFrame) {
    const CameraIntrinsics K = raytrace::equidistantFisheye(128, 190.0);
    const Pose T = upwardPose();
    Scene scene = floorScene(0.5f);
    const int white = addMaterial(scene, glm::vec3(0.8f));
    addBox(scene, "box", {-0.2f, 0.0f, -0.2f}, {0.2f, 0.4f, 0.2f}, white, Origin::Virtual);
    const CameraIntrinsics cam = smallCamera(160, 120, 110.0);
    const Pose view = lookAtPose({1.2, 1.0, 1.2}, {0, 0.2, 0});
    Renderer r(scene, cam);
    r.setEnvironmentCamera(fixedCamera(K, T));
    auto skyToward = [](glm::dvec3 dir) {
        return [dir](const glm::dvec3& d) {
            const double c = std::max(glm::dot(d, glm::normalize(dir)), 0.0);
            return glm::vec3(float(0.05 + 0.9 * std::pow(c, 4.0)));
        };
    };
    auto faces = [&] {
        const cv::Mat rv = r.readBuffer(kDirectRv);
        auto at = [&](glm::dvec3 w) {
            const auto px = cam.project(view.inverse() * w);
            EXPECT_TRUE(px.has_value());
            return rv.at<cv::Vec3f>(int(std::lround(px->y)), int(std::lround(px->x)))[0];
        };
        return std::pair<float, float>(at({0.2, 0.2, 0.0}), at({0.0, 0.2, 0.2}));  // +X, +Z face
    };
    r.updateEnvironment(test::renderEnvironmentView(K, T, skyToward({1, 0.5, 0})), 0.0);
    r.render({view, {}, false});
    const auto [xLit, zDark] = faces();
    r.updateEnvironment(test::renderEnvironmentView(K, T, skyToward({0, 0.5, 1})), 1.0 / 30);
    r.render({view, {}, false});
    const auto [xDark, zLit] = faces();
    std::printf("[ env turn ] +X face %.3f -> %.3f, +Z face %.3f -> %.3f\n", xLit, xDark, zDark,
                zLit);
    EXPECT_GT(xLit, 1.5f * zDark);
    EXPECT_GT(zLit, 1.5f * xDark);
}

// A camera mounted on the main camera takes its pose from the frame it is rendered with:
// T_world_env = T_world_main * T_main_env. Here it looks where the main camera looks.
TEST_F(EnvironmentPassTest, MountedCameraFollowsTheMainCamera) {
    const CameraIntrinsics K = raytrace::equidistantFisheye(96, 190.0);
    EnvironmentCameraSetup s;
    s.intrinsics = K;
    s.T_main_camera = Pose();  // identity: the fish-eye looks along the main camera's axis
    RendererOptions o;
    o.environment.mapWidth = 64;
    Renderer r(floorScene(0.5f), smallCamera(), o);
    r.setEnvironmentCamera(s);
    const cv::Mat grey(K.height, K.width, CV_8UC3, cv::Scalar::all(128));
    for (const glm::dvec3 target : {glm::dvec3(3, 1, 0), glm::dvec3(0, 1, -3)}) {
        const Pose main = lookAtPose({0, 1, 0}, target);
        r.updateEnvironment(grey, target.x);
        r.render({main, {}, false});
        const cv::Mat map = r.readEnvironmentMap();
        glm::dvec3 centroid(0.0);
        for (int y = 0; y < map.rows; ++y)
            for (int x = 0; x < map.cols; ++x)
                if (map.at<cv::Vec4f>(y, x)[3] > 0.5)
                    centroid += std::cos(M_PI / 2 - M_PI * (y + 0.5) / map.rows) *
                                test::equirectDirection(x + 0.5, y + 0.5, map.cols, map.rows);
        const glm::dvec3 axis = main.rotationMatrix() * glm::dvec3(0, 0, 1);
        EXPECT_GT(glm::dot(glm::normalize(centroid), axis), 0.99) << "target " << target.x;
    }
}

TEST_F(EnvironmentPassTest, BadInputIsRefusedWithAClearMessage) {
    Renderer r(floorScene(0.5f), smallCamera());
    const cv::Mat frame(64, 64, CV_8UC3, cv::Scalar::all(100));
    EXPECT_THROW(r.updateEnvironment(frame, 0.0), Error);  // no camera set
    r.setEnvironmentCamera(fixedCamera(raytrace::equidistantFisheye(96, 190.0), upwardPose()));
    try {
        r.updateEnvironment(frame, 0.0);
        FAIL() << "a 64x64 frame for a 96x96 calibration was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("96x96"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(r.environmentLive());

    CameraCalibration c;
    c.intrinsics = raytrace::equidistantFisheye(96, 190.0);
    EXPECT_THROW(EnvironmentCameraSetup::fromCalibration(c, "env.yaml"), FileError);
    c.T_parent_camera = Pose();
    c.extrinsicParent = "board";
    EXPECT_THROW(EnvironmentCameraSetup::fromCalibration(c, "env.yaml"), FileError);
    c.extrinsicParent = "main";
    EXPECT_TRUE(EnvironmentCameraSetup::fromCalibration(c, "env.yaml").T_main_camera.has_value());
}

}  // namespace
}  // namespace mirage::render
