// A translucent object's boundary against the Embree reference: what it lets through and what it
// reflects (docs/translucency.md "See-through", "Reflection").
//
// See-through: an optically thin virtual cube (tau 1.5 across, turned 15 degrees
// about +Y) in front of a real red wall, both lit by a real point light in front, composited into
// the reference's footage of the real scene. Compared over the cube's pixels: with the see-through
// the wall shows through the chord each camera ray crosses; without it (every translucent pixel
// opaque, its scattered light only) the cube misses the floor. A thick cube (tau 28 across) lets
// through only the short chords at its silhouette: inside them the two must agree, and over the
// whole cube the see-through must not be worse.
//
// Reflection: a thick, dark cube (tau 28 across, albedo 0.3, IOR 1.5) on a lit real floor, seen
// from low and to the side, so that two of its faces are seen at 55-70 degrees and mirror the
// floor and the wall. Without the reflection those faces are their scattered light only, darker
// than the reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <iostream>

#include <glm/gtc/matrix_transform.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/image/ImageIO.h"
#include "render/Renderer.h"
#include "render/passes/gbuffer/GBufferPass.h"
#include "tests/support/HeadlessGlSuite.h"
#include "tests/support/TestSupport.h"
#include "testscenes/ReferenceFrame.h"
#include "testscenes/TranslucentTestScenes.h"

namespace mirage::render {
namespace {

using namespace mirage::raytrace::test;
namespace fs = std::filesystem;

class TranslucentSeeThrough : public test::HeadlessGlSuite {};

// Measured on llvmpipe, 64 x 64 pixels, 16 voxels per side, the reference at 48 spp (seed 5),
// 2026-12-06 (with the boundary's reflection): the thin cube 23.4 dB with the see-through, 19.3 dB
// without; the thick cube 23.4 against 22.8 dB (its silhouette), its pixels 3 or more inside the
// silhouette within 0.1 codes. The dark cube's 4 x 4 block means: 25.4 dB with the reflection,
// 24.4 dB without.
constexpr double kThinFloorDb = 21.0;
constexpr double kThickInsideCodes = 1.0;  // mean |on - off| inside the thick cube, 8-bit codes
constexpr double kReflectionFloorDb = 24.9;
// The same view through a barrel lens (k1 -0.25, k2 0.06): 25.2 dB with the reflection, 24.3 dB
// without.
constexpr double kLensReflectionFloorDb = 24.8;

raytrace::RenderCamera cubeCamera() {
    // Focal length 120 px: the cube spans about 40 of the 64 pixels, the wall the rest.
    return lookAtCamera(64, 64, 120.0, {0.35, 0.3, 1.4}, {0, 0, 0});
}

raytrace::RenderCamera grazingCamera() {
    // Above and to the right: the side faces at 55-70 degrees mirror the floor beside the cube.
    return lookAtCamera(64, 64, 90.0, {0.95, 0.8, 0.75}, {0, -0.1, 0});
}

Scene seeThroughScene(float extinction, const fs::path& dir) {
    TranslucentSceneOptions o;
    o.extinction = extinction;  // 1/m across the 0.5 m cube
    o.albedo = {0.9f, 0.8f, 0.6f};
    o.ior = 1.3f;
    o.lightPosition = {0.6f, 0.8f, 1.2f};  // in front, above, to the right
    o.yawDegrees = 15.0f;
    Scene s = translucentTestScene(o, dir);
    addObject(s, "wall", boxPrimitive({-2.0f, -2.0f, -0.64f}, {2.0f, 2.0f, -0.6f}),
              lambert({0.8f, 0.25f, 0.2f}), glm::dmat4(1.0), Origin::Real);
    return s;
}

Scene reflectionScene(const fs::path& dir, float ior = 1.5f) {
    TranslucentSceneOptions o;
    o.extinction = 56.0f;
    o.albedo = {0.3f, 0.3f, 0.3f};
    o.ior = ior;
    o.lightPosition = {0.2f, 1.2f, 1.0f};  // above, in front
    o.lightIntensity = 4.0f;
    o.environment = 0.15f;
    o.yawDegrees = 15.0f;
    Scene s = translucentTestScene(o, dir);
    // The base colour carries the VPLs' indirect light into a translucent pixel: dark, as the
    // medium that scatters little.
    s.materials[0].baseColor = glm::vec4(0.05f, 0.05f, 0.05f, 1.0f);
    addObject(s, "wall", boxPrimitive({-2.0f, -0.29f, -0.84f}, {2.0f, 2.0f, -0.8f}),
              lambert({0.8f, 0.25f, 0.2f}), glm::dmat4(1.0), Origin::Real);
    addObject(s, "floor", boxPrimitive({-2.0f, -0.29f, -0.8f}, {2.0f, -0.25f, 2.0f}),
              lambert({0.7f, 0.7f, 0.6f}), glm::dmat4(1.0), Origin::Real);
    return s;
}

struct Composite {
    cv::Mat srgb;  // CV_8UC3 BGR
    cv::Mat cube;  // CV_8U: pixels whose first hit is the cube
};

Composite renderRealtime(const Scene& scene, const raytrace::RenderCamera& cam,
                         const cv::Mat& footage, const TranslucencyOptions& translucency) {
    RendererOptions opt;
    opt.translucency = translucency;
    opt.translucency.vnmResolution = 16;
    Renderer r(scene, cam.intrinsics, opt);
    const FrameReport& rep = r.render({cam.T_world_camera, footage, true});
    EXPECT_TRUE(rep.ran("translucency")) << rep.summary();
    EXPECT_TRUE(cv::checkRange(r.compositeLinear())) << "NaN/Inf in the composite";
    Composite c;
    c.srgb = r.compositeSrgb();
    // The cube's pixels: G-buffer positions inside the cube (turned 15 degrees about +Y).
    const cv::Mat position = r.readBuffer(kGBufferPosition);
    const glm::dmat4 fromWorld =
        glm::rotate(glm::dmat4(1.0), glm::radians(-15.0), glm::dvec3(0, 1, 0));
    c.cube = cv::Mat(position.size(), CV_8U, cv::Scalar(0));
    for (int y = 0; y < position.rows; ++y)
        for (int x = 0; x < position.cols; ++x) {
            const cv::Vec3f w = position.at<cv::Vec3f>(y, x);
            const glm::dvec3 q = glm::dvec3(fromWorld * glm::dvec4(w[0], w[1], w[2], 1.0));
            const double inside = std::max({std::abs(q.x), std::abs(q.y), std::abs(q.z)});
            if (cv::norm(w) > 0.0 && inside < 0.252) c.cube.at<uint8_t>(y, x) = 255;
        }
    return c;
}

// The reference frame, and the real-time composites into its footage with the defaults (`on`)
// and with `without` (`off`).
struct OnOff {
    test::ReferenceFrame ref;
    Composite on, off;
};

OnOff renderOnOff(const Scene& scene, const raytrace::RenderCamera& cam,
                  const TranslucencyOptions& without) {
    OnOff r;
    r.ref = test::renderReferenceFrame(scene, cam.intrinsics, cam.T_world_camera, 48, 5, false);
    r.on = renderRealtime(scene, cam, r.ref.footage, TranslucencyOptions{});
    r.off = renderRealtime(scene, cam, r.ref.footage, without);
    return r;
}

struct Judged {
    double on = 0, off = 0;
    double insideCodes = 0;  // mean |on - off| (8-bit codes) 3 or more pixels inside the cube
};

Judged judge(float extinction, const std::string& name) {
    const fs::path dir = mirage::test::outputDir("translucent_see_through_" + name);
    const Scene scene = seeThroughScene(extinction, dir);
    TranslucencyOptions opaque;
    opaque.seeThrough = false;
    const auto [ref, on, off] = renderOnOff(scene, cubeCamera(), opaque);
    EXPECT_GT(cv::countNonZero(on.cube), 600) << name;
    Judged j{test::psnr(on.srgb, ref.composite, 255.0, on.cube),
             test::psnr(off.srgb, ref.composite, 255.0, on.cube), 0.0};
    cv::Mat inside;
    cv::erode(on.cube, inside, cv::Mat::ones(7, 7, CV_8U));
    j.insideCodes = test::meanAbsDiff(on.srgb, off.srgb, inside);
    std::cout << "[ see-through ] " << name << ": PSNR over the cube " << j.on
              << " dB with the see-through, " << j.off << " dB opaque; inside the silhouette "
              << j.insideCodes << " codes apart\n";
    cv::Mat row;
    cv::hconcat(std::vector<cv::Mat>{ref.footage, ref.composite, on.srgb, off.srgb}, row);
    cv::resize(row, row, {}, 4, 4, cv::INTER_NEAREST);
    writeBgr8(dir / "footage_reference_on_off.png", row);
    return j;
}

// The thin cube, judged once for both tests (a reference and two real-time renders).
const Judged& thinCube() {
    static const Judged thin = judge(3.0f, "thin");
    return thin;
}

TEST_F(TranslucentSeeThrough, ThinCubeShowsTheWallBehindLikeTheReference) {
    const Judged& thin = thinCube();
    EXPECT_GT(thin.on, kThinFloorDb);
    EXPECT_LT(thin.off, kThinFloorDb) << "the must-fail: an opaque thin cube";
}

TEST_F(TranslucentSeeThrough, ThickCubeLetsThroughOnlyAtItsSilhouette) {
    const Judged thick = judge(56.0f, "thick");
    EXPECT_GT(thick.on, thick.off);
    EXPECT_LT(thick.insideCodes, kThickInsideCodes);
    const Judged& thin = thinCube();
    EXPECT_GT(thin.insideCodes, 10 * kThickInsideCodes) << "the check can fail: a thin cube";
}

// PSNR of the dark cube's 4 x 4 block means (blocks wholly on the cube) with and without the
// boundary's reflection, against the reference: its noise (a dark medium at 48 spp) averaged
// out, the faces' levels kept. `cube`: the cube's pixels from the canvas G-buffer (a camera
// without distortion, whose canvas is the image) or, through a lens, from the reference's
// coverage (the composite is the distorted image, the G-buffer the undistorted canvas).
struct ReflectionJudged {
    double on = 0, off = 0;
};

ReflectionJudged judgeReflection(const raytrace::RenderCamera& cam, const std::string& name,
                                 bool cubeFromReference) {
    const fs::path dir = mirage::test::outputDir(name);
    const Scene scene = reflectionScene(dir);
    TranslucencyOptions matte;
    matte.surfaceReflection = false;
    const auto [ref, on, off] = renderOnOff(scene, cam, matte);
    const cv::Mat cube = cubeFromReference ? cv::Mat(ref.images.virtualCoverage > 0.99f) : on.cube;
    EXPECT_GT(cv::countNonZero(cube), 600);
    auto blocks = [](const cv::Mat& m) {
        cv::Mat f, out;
        m.convertTo(f, CV_32F);
        cv::resize(f, out, {}, 0.25, 0.25, cv::INTER_AREA);
        return out;
    };
    cv::Mat blockMask;
    cv::resize(cube, blockMask, {}, 0.25, 0.25, cv::INTER_AREA);
    blockMask = blockMask > 254;
    const ReflectionJudged j{test::psnr(blocks(on.srgb), blocks(ref.composite), 255.0, blockMask),
                             test::psnr(blocks(off.srgb), blocks(ref.composite), 255.0, blockMask)};
    const cv::Scalar meanRef = cv::mean(ref.composite, cube), meanOn = cv::mean(on.srgb, cube),
                     meanOff = cv::mean(off.srgb, cube);
    std::cout << "[ reflection ] " << name << ": " << cv::countNonZero(blockMask)
              << " blocks; PSNR over them " << j.on << " dB with the reflection, " << j.off
              << " dB without; mean code (B G R) reference " << meanRef << ", with " << meanOn
              << ", without " << meanOff << "\n";
    cv::Mat row;
    cv::hconcat(std::vector<cv::Mat>{ref.footage, ref.composite, on.srgb, off.srgb}, row);
    cv::resize(row, row, {}, 4, 4, cv::INTER_NEAREST);
    writeBgr8(dir / "footage_reference_on_off.png", row);
    return j;
}

TEST_F(TranslucentSeeThrough, GrazingFacesReflectTheFloorLikeTheReference) {
    const ReflectionJudged j = judgeReflection(grazingCamera(), "translucent_reflection", false);
    EXPECT_GT(j.on, kReflectionFloorDb);
    EXPECT_LT(j.off, kReflectionFloorDb) << "the must-fail: no reflection";
}

// The same through a strong barrel lens: the reflection's footage is read where the lens puts
// the mirrored real point in the camera image (the composite's canvas-to-camera map), not at
// its canvas pixel.
TEST_F(TranslucentSeeThrough, GrazingFacesReflectTheFloorThroughALens) {
    raytrace::RenderCamera cam = grazingCamera();
    cam.intrinsics.distortion = {-0.25, 0.06, 0.0, 0.0, 0.0};
    const ReflectionJudged j = judgeReflection(cam, "translucent_reflection_lens", true);
    EXPECT_GT(j.on, kLensReflectionFloorDb);
    EXPECT_LT(j.off, kLensReflectionFloorDb) << "the must-fail: no reflection";
}

TEST_F(TranslucentSeeThrough, ReflectionVanishesAsTheIorNearsOne) {
    // IOR 1.001: F_r is at most ~1e-3 short of grazing, so the reflection must change the
    // cube's pixels by well under a code; at IOR 1.5 the same view differs by several codes
    // (the check can fail).
    auto apart = [](float ior) {
        const fs::path dir = mirage::test::outputDir("translucent_reflection_ior");
        const Scene scene = reflectionScene(dir, ior);
        const raytrace::RenderCamera cam = grazingCamera();
        const cv::Mat footage(cam.intrinsics.height, cam.intrinsics.width, CV_8UC3,
                              cv::Scalar(120, 130, 140));
        TranslucencyOptions reflecting, matte;
        matte.surfaceReflection = false;
        const Composite on = renderRealtime(scene, cam, footage, reflecting);
        const Composite off = renderRealtime(scene, cam, footage, matte);
        return test::meanAbsDiff(on.srgb, off.srgb, on.cube);
    };
    const double nearOne = apart(1.001f), glass = apart(1.5f);
    std::cout << "[ reflection ] mean |with - without| over the cube: " << nearOne
              << " codes at IOR 1.001, " << glass << " at IOR 1.5\n";
    EXPECT_LT(nearOne, 0.5);
    EXPECT_GT(glass, 2.0);
}

}  // namespace
}  // namespace mirage::render
