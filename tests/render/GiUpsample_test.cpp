// The direct-light pass upsamples the filtered indirect light (gifilter's GatherLight) and adds
// it in the same full-screen pass: LRv / LR are direct + indirect light, DirectRv / DirectR the
// direct light alone when RendererOptions::direct.keepDirectLight asks for it, and without VPL
// light the GI solutions are the direct light.
#include <gtest/gtest.h>

#include <iostream>
#include <vector>

#include <opencv2/core.hpp>

#include "core/scene/Scene.h"
#include "render/FrameContext.h"
#include "render/Renderer.h"
#include "render/passes/direct/DirectLightPass.h"
#include "tests/support/HeadlessGlSuite.h"
#include "tests/support/TestSupport.h"
#include "testscenes/RenderTestScenes.h"

namespace mirage::render {
namespace {

class GiUpsample : public test::HeadlessGlSuite {};

const CameraIntrinsics kCamera = test::smallCamera(160, 120, 130.0);
const Pose kPose = test::lookAtPose({0.05, 0.40, 0.60}, {-0.05, 0.02, 0.0});

struct Buffers {
    cv::Mat lightRv, lightR, directRv, directR, composite;
    bool gathered = false;  // gifilter ran (VPL light this frame)
};

Buffers render(const Scene& scene, bool keepDirect, int vplCount) {
    RendererOptions o;
    o.vpl.count = vplCount;
    o.temporalBlend = 0.0f;
    o.direct.keepDirectLight = keepDirect;
    Renderer r(scene, kCamera, o);
    const cv::Mat footage(kCamera.height, kCamera.width, CV_8UC3, cv::Scalar(90, 110, 130));
    const FrameReport& report = r.render({kPose, footage, true});
    Buffers b;
    b.gathered = report.ran("gifilter");
    b.lightRv = r.readBuffer(kLRv);
    b.lightR = r.readBuffer(kLR);
    if (keepDirect || !b.gathered) {
        b.directRv = r.readBuffer(kDirectRv);
        b.directR = r.readBuffer(kDirectR);
    }
    b.composite = r.compositeLinear();
    return b;
}

double maxAbsDiff(const cv::Mat& a, const cv::Mat& b) {
    return cv::norm(a, b, cv::NORM_INF);
}

TEST_F(GiUpsample, DirectPassSumsDirectAndUpsampledIndirectLight) {
    const Scene scene = loadScene(test::dataDir() / "scenes" / "tabletop" / "tabletop.gltf");
    const Buffers kept = render(scene, true, 64);
    ASSERT_TRUE(kept.gathered);
    // The indirect part: LRv - DirectRv, non-negative, and bright enough to see on most of the
    // lit pixels (a pass that dropped it would leave LRv == DirectRv).
    cv::Mat indirect = kept.lightRv - kept.directRv;
    double minIndirect = 0.0, maxIndirect = 0.0;
    cv::minMaxLoc(indirect.reshape(1), &minIndirect, &maxIndirect);
    std::vector<cv::Mat> channels;
    cv::split(indirect, channels);
    const int lit = cv::countNonZero(channels[0] > 1e-3);
    std::cout << "indirect light: " << lit << " of " << indirect.total()
              << " pixels above 1e-3, max " << maxIndirect << "\n";
    EXPECT_GT(minIndirect, -2e-3);  // half-float rounding of the sum
    EXPECT_GT(lit, int(indirect.total() / 30));
    EXPECT_GT(maxIndirect, 0.01);
    // The real-only solution too (real light bouncing off real surfaces).
    EXPECT_GT(cv::mean(kept.lightR - kept.directR)[0], 0.0);

    // Keeping the direct light apart changes neither the sum nor the composite.
    const Buffers plain = render(scene, false, 64);
    EXPECT_LT(maxAbsDiff(plain.lightRv, kept.lightRv), 1e-5);
    EXPECT_LT(maxAbsDiff(plain.lightR, kept.lightR), 1e-5);
    EXPECT_LT(maxAbsDiff(plain.composite, kept.composite), 1e-5);
    EXPECT_TRUE(plain.directRv.empty());  // not produced: LRv is the sum
}

TEST_F(GiUpsample, WithoutVplLightTheSolutionsAreTheDirectLight) {
    const Scene scene = loadScene(test::dataDir() / "scenes" / "tabletop" / "tabletop.gltf");
    const Buffers noVpls = render(scene, false, 0);
    ASSERT_FALSE(noVpls.gathered);
    EXPECT_EQ(maxAbsDiff(noVpls.lightRv, noVpls.directRv), 0.0);
    EXPECT_EQ(maxAbsDiff(noVpls.lightR, noVpls.directR), 0.0);
    // And the direct light is the same as in a frame with VPLs (the indirect part added apart).
    const Buffers kept = render(scene, true, 64);
    EXPECT_LT(maxAbsDiff(noVpls.directRv, kept.directRv), 1e-5);
}

}  // namespace
}  // namespace mirage::render
