// A translucent object lets through what lies behind it (docs/translucency.md "See-through"),
// against the Embree reference: an optically thin virtual cube (tau 1.5 across, turned 15 degrees
// about +Y) in front of a real red wall, both lit by a real point light in front, composited into
// the reference's footage of the real scene. Compared over the cube's pixels: with the see-through
// the wall shows through the chord each camera ray crosses; without it (every translucent pixel
// opaque, its scattered light only) the cube misses the floor. A thick cube (tau 28 across) lets
// through only the short chords at its silhouette: inside them the two must agree, and over the
// whole cube the see-through must not be worse.
#include <gtest/gtest.h>

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
// 2026-12-05: the thin cube 23.1 dB with the see-through, 19.0 dB without; the thick cube 23.1
// against 22.5 dB (its silhouette), its pixels 3 or more inside the silhouette within 0.1 codes.
constexpr double kThinFloorDb = 21.0;
constexpr double kThickInsideCodes = 1.0;  // mean |on - off| inside the thick cube, 8-bit codes

raytrace::RenderCamera cubeCamera() {
    // Focal length 120 px: the cube spans about 40 of the 64 pixels, the wall the rest.
    return lookAtCamera(64, 64, 120.0, {0.35, 0.3, 1.4}, {0, 0, 0});
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

struct Composite {
    cv::Mat srgb;  // CV_8UC3 BGR
    cv::Mat cube;  // CV_8U: pixels whose first hit is the cube
};

Composite renderRealtime(const Scene& scene, const cv::Mat& footage, bool seeThrough) {
    const raytrace::RenderCamera cam = cubeCamera();
    RendererOptions opt;
    opt.translucency.vnmResolution = 16;
    opt.translucency.seeThrough = seeThrough;
    Renderer r(scene, cam.intrinsics, opt);
    const FrameReport& rep = r.render({cam.T_world_camera, footage, true});
    EXPECT_TRUE(rep.ran("translucency")) << rep.summary();
    EXPECT_TRUE(cv::checkRange(r.compositeLinear())) << "NaN/Inf in the composite";
    Composite c;
    c.srgb = r.compositeSrgb();
    const cv::Mat position = r.readBuffer(kGBufferPosition);
    c.cube = cv::Mat(position.size(), CV_8U, cv::Scalar(0));
    for (int y = 0; y < position.rows; ++y)
        for (int x = 0; x < position.cols; ++x) {
            const cv::Vec3f p = position.at<cv::Vec3f>(y, x);
            if (cv::norm(p) > 0.0 && cv::norm(p) < 0.5) c.cube.at<uint8_t>(y, x) = 255;
        }
    return c;
}

struct Judged {
    double on = 0, off = 0;
    double insideCodes = 0;  // mean |on - off| (8-bit codes) 3 or more pixels inside the cube
};

Judged judge(float extinction, const std::string& name) {
    const fs::path dir = mirage::test::outputDir("translucent_see_through_" + name);
    const Scene scene = seeThroughScene(extinction, dir);
    const raytrace::RenderCamera cam = cubeCamera();
    const test::ReferenceFrame ref =
        test::renderReferenceFrame(scene, cam.intrinsics, cam.T_world_camera, 48, 5, false);
    const Composite on = renderRealtime(scene, ref.footage, true);
    const Composite off = renderRealtime(scene, ref.footage, false);
    EXPECT_GT(cv::countNonZero(on.cube), 600) << name;
    Judged j{test::psnr(on.srgb, ref.composite, 255.0, on.cube),
             test::psnr(off.srgb, ref.composite, 255.0, on.cube), 0.0};
    cv::Mat inside, diff;
    cv::erode(on.cube, inside, cv::Mat::ones(7, 7, CV_8U));
    cv::absdiff(on.srgb, off.srgb, diff);
    const cv::Scalar d = cv::mean(diff, inside);
    j.insideCodes = (d[0] + d[1] + d[2]) / 3.0;
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

}  // namespace
}  // namespace mirage::render
