// The VPLs' per-frame rotation (VplOptions::temporalRotation, render/passes/vpl) against the
// Embree reference: a red virtual box on a real table under a real spot light (its bounce
// colours the table), few VPLs, a camera holding still for 12 frames with the GI filter's
// temporal smoothing. The same VPLs every frame leave the structured error of one VPL set; a
// rotated set lets the smoothing average several. Judged over the pixels the box changes: the
// rotated frame closer to the reference than the fixed one (the must-fail: the fixed set fails
// the floor the rotated one meets), the first frame identical (frame 0 has no offset), and what
// it costs in steadiness: the rotated frames change from one to the next (below a code on
// average from 64 VPLs on, the smoothing's average of the sets).
// docs/realtime-renderer.md, "VPLs rotated over frames", has the figures.
#include <gtest/gtest.h>

#include <cstdio>

#include <opencv2/core.hpp>

#include "core/gl/Context.h"
#include "render/Renderer.h"
#include "render/passes/vpl/VplPass.h"
#include "tests/support/TestSupport.h"
#include "testscenes/ReferenceFrame.h"
#include "testscenes/RenderTestScenes.h"

namespace mirage::render {
namespace {

struct Reference {
    Scene scene;
    CameraIntrinsics cam = test::smallCamera(160, 120);
    Pose pose = test::lookAtPose({0.6, 1.2, 1.4}, {0, 0.1, 0});
    cv::Mat footage, truthSrgb, influenced;
};

const Reference& reference() {
    static const Reference r = [] {
        Reference s;
        const int table = test::addMaterial(s.scene, glm::vec3(0.7f));
        const int red = test::addMaterial(s.scene, glm::vec3(0.9f, 0.15f, 0.1f));
        test::addFloor(s.scene, "table", 0.0f, 4.0f, table, Origin::Real);
        test::addBox(s.scene, "virtual box", {-0.2f, 0.0f, -0.2f}, {0.2f, 0.4f, 0.2f}, red,
                     Origin::Virtual);
        const glm::vec3 light(0.9f, 1.4f, 0.6f);
        test::addLight(s.scene, Light::Type::Spot, light,
                       glm::normalize(glm::vec3(0.0f, 0.1f, 0.0f) - light), 8.0f, Origin::Real,
                       1.0f, 0.9f);
        const test::ReferenceFrame f = test::renderReferenceFrame(s.scene, s.cam, s.pose, 64, 7,
                                                                  /*caustics=*/false);
        s.footage = f.footage;
        s.truthSrgb = f.composite;
        s.influenced = test::influencedPixels(f.images);
        return s;
    }();
    return r;
}

struct Frames {
    cv::Mat first, last, beforeLast;
};

Frames render(bool rotate, int frames, int vpls = 16) {
    const Reference& ref = reference();
    RendererOptions o;
    o.vpl.count = vpls;
    o.vpl.temporalRotation = rotate;
    Renderer r(ref.scene, ref.cam, o);
    Frames out;
    for (int k = 0; k < frames; ++k) {
        r.render({ref.pose, ref.footage, k == 0});
        if (k == 0) out.first = r.compositeSrgb();
        if (k == frames - 2) out.beforeLast = r.compositeSrgb();
        if (k == frames - 1) out.last = r.compositeSrgb();
    }
    return out;
}

// Measured (llvmpipe, 12 frames, over the box's 6,594 influenced pixels), fixed / rotated:
// 16 VPLs 28.61 / 29.20 dB, 64 VPLs 26.11 / 30.26 dB, 256 VPLs 30.54 / 31.45 dB; the rotated
// frames change by 1.98, 0.76 and 0.48 codes on average from one frame to the next.
constexpr int kFrames = 12;
constexpr int kJudgedVpls = 64;
constexpr double kMinRotatedPsnr = 29.5;  // at kJudgedVpls
constexpr double kMaxChangeCodes = 1.0;   // at 64 VPLs and more

TEST(VplRotation, RotatedVplsAverageTowardsTheReferenceAndFixedOnesFailTheFloor) {
    gl::Context context = gl::Context::headless();
    const Reference& ref = reference();
    ASSERT_GT(cv::countNonZero(ref.influenced), 500);
    for (int n : {16, 64, 256}) {
        const Frames fixed = render(false, kFrames, n), rotated = render(true, kFrames, n);
        const double pFixed = test::psnr(fixed.last, ref.truthSrgb, 255.0, ref.influenced);
        const double pRotated = test::psnr(rotated.last, ref.truthSrgb, 255.0, ref.influenced);
        const double change = test::meanAbsDiff(rotated.last, rotated.beforeLast, ref.influenced);
        std::printf(
            "%d VPLs, frame %d against the reference over %d px: fixed %.2f dB, rotated "
            "%.2f dB; the rotated frame changes by %.3f codes\n",
            n, kFrames - 1, cv::countNonZero(ref.influenced), pFixed, pRotated, change);
        EXPECT_GT(pRotated, pFixed) << n << " VPLs";
        EXPECT_EQ(test::meanAbsDiff(fixed.first, rotated.first, ref.influenced), 0.0)
            << "frame 0 has no offset";
        if (n >= kJudgedVpls) {
            EXPECT_LT(change, kMaxChangeCodes) << n << " VPLs";
        }
        if (n == kJudgedVpls) {
            EXPECT_GE(pRotated, kMinRotatedPsnr);
            EXPECT_LT(pFixed, kMinRotatedPsnr) << "must-fail: one VPL set's structured error";
        }
    }
}

TEST(VplRotation, OffsetsFillTheSquareAndStartAtZero) {
    EXPECT_EQ(vplSampleOffset(0), glm::vec2(0.0f));
    // 16 consecutive frames: at least one offset in each quarter of the square (no clumping).
    int quarters[4] = {};
    for (int f = 1; f <= 16; ++f) {
        const glm::vec2 o = vplSampleOffset(f);
        ASSERT_TRUE(o.x >= 0.0f && o.x < 1.0f && o.y >= 0.0f && o.y < 1.0f) << f;
        ++quarters[(o.x >= 0.5f ? 1 : 0) + (o.y >= 0.5f ? 2 : 0)];
    }
    for (int q : quarters) EXPECT_GE(q, 2);
}

}  // namespace
}  // namespace mirage::render
