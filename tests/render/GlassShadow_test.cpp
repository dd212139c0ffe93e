// Shadows through glass against the Embree reference with caustics ON (the reference carries the
// light through glass by photon mapping). A virtual glass plate above a real table under a real
// point light: the real-time shadow maps let the glass transmit (Fresnel-, colour- and
// absorption-weighted), so the table under the plate keeps about the light the reference's
// caustic brings there; treating the glass as an opaque occluder (the old behaviour) leaves it
// dark and must fail. The routing (real-only shadow maps) is checked on L_r.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include <opencv2/core.hpp>

#include "core/gl/Context.h"
#include "core/image/ImageIO.h"
#include "render/Renderer.h"
#include "render/passes/direct/DirectLightPass.h"
#include "render/raytrace/DifferentialRendering.h"
#include "render/raytrace/EmbreeDevice.h"
#include "tests/support/TestSupport.h"
#include "testscenes/CausticTestScenes.h"
#include "testscenes/ReferenceFrame.h"

namespace mirage::render {
namespace {

constexpr double kGlassShadowTolerance = 0.15;  // measured: -6 % (docs/caustics.md)

struct Reference {
    cv::Mat footage;    // 8-bit sRGB BGR: the reference's real-only render
    cv::Mat composite;  // linear RGB: the reference differential composite
};

Reference referenceComposite(const test::CausticScene& s) {
    const test::ReferenceFrame f = test::renderReferenceFrame(s.scene, s.cam, s.pose, 32, 5);
    return {f.footage, f.compositeLinear};
}

// Mean luminance (linear) over the glass's straight shadow in the reference composite, the
// real-time composite with glass transmitting in the shadow maps, and with glass opaque.
TEST(GlassShadow, ShadowOfGlassIsLitLikeTheReferenceAndOpaqueFails) {
    gl::Context context = gl::Context::headless();
    test::CausticSceneOptions o;
    o.lightType = Light::Type::Point;  // no caustic pass for point lights: the shadow maps carry it
    o.object = test::CausticObject::Slab;  // a plate: straight transmission is what happens
    o.attenuationColor = glm::vec3(0.9f, 0.6f, 0.3f);  // amber: the shadow must be tinted
    o.attenuationDistance = 0.05f;
    o.lightPos = glm::vec3(0.35f, 1.0f, 0.05f);
    test::CausticScene s = test::makeCausticScene(o);
    s.cam = test::smallCamera(96, 72, 80.0);
    s.pose = test::lookAtPose({0.0, 0.95, 0.85}, {-0.12, 0.0, 0.0});
    const cv::Mat mask = test::straightShadowMask(s);
    ASSERT_GT(cv::countNonZero(mask), 40);
    const Reference ref = referenceComposite(s);

    auto realtime = [&](bool glassShadows, cv::Mat* lr = nullptr) {
        RendererOptions opt;
        opt.temporalBlend = 0.0f;
        opt.shadow.glass = glassShadows;
        Renderer r(s.scene, s.cam, opt);
        r.render({s.pose, ref.footage, true});
        const cv::Mat lin = r.compositeLinear();
        EXPECT_TRUE(cv::checkRange(lin));
        if (lr) *lr = r.readBuffer(kLR);
        return lin;
    };
    cv::Mat lr;
    const cv::Mat glass = realtime(true, &lr), opaque = realtime(false);
    const double yRef = test::meanLuminance(ref.composite, mask),
                 yGlass = test::meanLuminance(glass, mask),
                 yOpaque = test::meanLuminance(opaque, mask),
                 yFootage = test::meanLuminance(srgbBgr8ToLinearRgb(ref.footage), mask);
    const cv::Scalar cRef = cv::mean(ref.composite, mask), cGlass = cv::mean(glass, mask);
    std::cout << "[ glass shadow ] mean luminance over " << cv::countNonZero(mask)
              << " shadow pixels: reference " << yRef << ", glass transmits " << yGlass
              << ", opaque " << yOpaque << ", footage (no sphere) " << yFootage
              << "; red/blue: reference " << cRef[0] / cRef[2] << ", real-time "
              << cGlass[0] / cGlass[2] << "\n";
    // Measured (llvmpipe, reference 32 spp seed 5): see docs/caustics.md.
    EXPECT_NEAR(yGlass / yRef, 1.0, kGlassShadowTolerance);
    EXPECT_LT(yOpaque / yRef, 1.0 - kGlassShadowTolerance);  // the must-fail: an opaque shadow
    // Tinted like the reference: amber glass lets red through more than blue.
    EXPECT_GT(cGlass[0] / cGlass[2], 1.3);
    EXPECT_NEAR((cGlass[0] / cGlass[2]) / (cRef[0] / cRef[2]), 1.0, 0.1);
    // Routing: a virtual plate does not shadow L_r (the real-only maps hold no glass).
    EXPECT_GT(test::meanLuminance(lr, mask), yGlass);
}

}  // namespace
}  // namespace mirage::render

namespace mirage::render {
namespace {

// What the real-time path does not do, measured: a point light gets no caustic pass, so the
// light through a CURVED glass goes straight through in the shadow maps instead of being focused.
// The caustic scene's sphere under a point light: the reference focuses the light into a small
// bright spot inside the straight shadow; the real-time straight shadow is lit evenly. Figures in
// docs/caustics.md; asserted: no caustic pass for a point light, everything finite, and the
// straight-line transmission keeps the light's amount there within 35 % (its distribution is
// what it gets wrong).
TEST(GlassShadow, PointLightThroughCurvedGlassIsTheDocumentedError) {
    gl::Context context = gl::Context::headless();
    test::CausticSceneOptions o;
    o.lightType = Light::Type::Point;
    const test::CausticScene s = test::makeCausticScene(o);
    const cv::Mat mask = test::straightShadowMask(s, 0.8);
    ASSERT_GT(cv::countNonZero(mask), 40);
    const Reference ref = referenceComposite(s);
    RendererOptions opt;
    opt.temporalBlend = 0.0f;
    Renderer r(s.scene, s.cam, opt);
    const FrameReport& rep = r.render({s.pose, ref.footage, true});
    EXPECT_FALSE(rep.ran("photongbuf")) << rep.summary();
    const cv::Mat rt = r.compositeLinear();
    ASSERT_TRUE(cv::checkRange(rt));
    const double yRef = test::meanLuminance(ref.composite, mask),
                 yRt = test::meanLuminance(rt, mask);
    const double psnr =
        test::psnr(linearRgbToSrgbBgr8(rt), linearRgbToSrgbBgr8(ref.composite), 255.0, mask);
    std::cout << "[ glass shadow ] point light through the sphere, " << cv::countNonZero(mask)
              << " px of its straight shadow: mean luminance reference " << yRef << ", real-time "
              << yRt << "; PSNR " << psnr << " dB\n";
    EXPECT_NEAR(yRt / yRef, 1.0, 0.35);
}

}  // namespace
}  // namespace mirage::render
