// A caustic seen through the glass (docs/caustics.md, "Caustics seen in reflections and
// refractions"): the glass sphere's own caustic on the real table, seen by a camera on the
// light's side through the sphere, against the Embree reference with caustics ON. The camera
// does not see the table point the refracted ray reaches, so the caustic comes from the photon
// grid gathered at the refracted hits into L'_rv. Compared over the caustic region inside the
// sphere: the sphere's pixels (1.5 px in from its outline) where the reference's caustic adds
// > 5 % to L_rv. Must-fails: caustics off, the gather off, the glass's IOR off by 0.2.
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/gl/Context.h"
#include "core/image/ImageIO.h"
#include "render/Renderer.h"
#include "render/passes/specular/SpecularLightPass.h"
#include "tests/render/CausticReference.h"
#include "tests/support/TestSupport.h"
#include "testscenes/CausticTestScenes.h"

namespace mirage::render {
namespace {

using test::linearLuminance;

using test::sphereView;

// The caustic scene (CausticTestScenes.h: a virtual glass sphere, r = 0.1 m, IOR 1.5, 7.5 cm
// above a real table, a real spot 1 m away at 60 degrees elevation on the +X side; its caustic
// lies on the table around (-0.1, 0, 0)), seen from the light's side and above, so that the
// caustic lies behind the sphere: the camera sees it only through the glass.
test::CausticScene throughGlassScene(const test::CausticSceneOptions& o = {}) {
    test::CausticScene s = test::makeCausticScene(o);
    s.cam = test::smallCamera(128, 96, 260.0);
    s.pose = test::lookAtPose({0.5, 0.7, 0.3}, {0.0, 0.15, 0.0});
    return s;
}

struct Realtime {
    cv::Mat composite;  // sRGB8 BGR
    cv::Mat specRv;     // L'_rv, linear RGB
    FrameReport report;
};

Realtime realtime(const test::CausticScene& s, const cv::Mat& footage, RendererOptions opt = {}) {
    opt.temporalBlend = 0.0f;
    Renderer r(s.scene, s.cam, opt);
    Realtime out;
    out.report = r.render({s.pose, footage, true});
    out.composite = r.compositeSrgb();
    EXPECT_TRUE(cv::checkRange(r.compositeLinear())) << "NaN/Inf in the composite";
    out.specRv = out.report.ran("speclight") ? r.readBuffer(kSpecularRv)
                                             : cv::Mat::zeros(footage.size(), CV_32FC3);
    EXPECT_TRUE(cv::checkRange(out.specRv)) << "NaN/Inf in L'_rv";
    return out;
}

void save(const std::string& name, const test::CausticReferenceRender& ref, const cv::Mat& region,
          const std::vector<const Realtime*>& rts) {
    const auto dir = std::filesystem::path(MIRAGE_TEST_OUTPUT_DIR) / "caustics";
    std::filesystem::create_directories(dir);
    std::vector<cv::Mat> row;
    for (const Realtime* rt : rts) row.push_back(rt->composite);
    row.push_back(ref.compositeSrgb);
    cv::Mat region3;
    cv::cvtColor(region, region3, cv::COLOR_GRAY2BGR);
    row.push_back(region3);
    cv::Mat side;
    cv::hconcat(row, side);
    cv::resize(side, side, cv::Size(), 3.0, 3.0, cv::INTER_NEAREST);
    writeBgr8(dir / (name + ".png"), side);
}

// Floors from measurement (llvmpipe; reference 16 spp, seed 13; docs/caustics.md): region
// 26.4 dB, flux 1.00 x the reference's; caustics off 12.2 dB, gather off 9.6 dB, IOR 1.7 for
// 1.5 16.4 dB.
constexpr double kRegionPsnr = 25.0, kFluxTolerance = 0.15;

TEST(CausticThroughGlass, CausticSeenThroughTheSphereMatchesReferenceAndBrokenRendersFail) {
    gl::Context context = gl::Context::headless();
    const test::CausticScene s = throughGlassScene();
    const test::CausticReferenceRender ref = test::renderCausticReference(s, 16, 13);
    const cv::Mat sphere = test::sphereMask(sphereView(s), 1.5);
    const cv::Mat region = ref.region & sphere;
    const int regionPx = cv::countNonZero(region);
    std::cout << "[ caustic through glass ] sphere " << cv::countNonZero(sphere) << " px, region "
              << regionPx << " px\n";
    ASSERT_GT(regionPx, 40) << "the reference shows no caustic through the sphere";

    const Realtime on = realtime(s, ref.footage);
    ASSERT_TRUE(on.report.ran("photongrid")) << on.report.summary();
    RendererOptions noCaustics;
    noCaustics.caustic.enabled = false;
    const Realtime off = realtime(s, ref.footage, noCaustics);
    RendererOptions noGather;
    noGather.caustic.gather = false;
    const Realtime gatherOff = realtime(s, ref.footage, noGather);
    test::CausticSceneOptions wrongIor;
    wrongIor.ior = 1.7f;
    const Realtime ior = realtime(throughGlassScene(wrongIor), ref.footage);
    save("through_glass", ref, region, {&off, &on, &ior});

    const auto regionPsnr = [&](const Realtime& rt) {
        return test::psnr(rt.composite, ref.compositeSrgb, 255.0, region);
    };
    // The caustic's flux seen through the glass: L'_rv with the gather on minus off over the
    // region (the refraction weight included, as in the composite), against the reference's
    // caustic there.
    cv::Mat gathered = cv::Mat::zeros(region.size(), CV_32F), refCaustic = gathered.clone();
    cv::Mat(cv::max(linearLuminance(on.specRv - gatherOff.specRv), 0.0f)).copyTo(gathered, region);
    linearLuminance(ref.caustic).copyTo(refCaustic, region);
    const double fluxRatio = cv::sum(gathered)[0] / cv::sum(refCaustic)[0];
    std::cout << "[ caustic through glass ] region PSNR " << regionPsnr(on) << " dB, SSIM "
              << test::ssim(on.composite, ref.compositeSrgb, 255.0, region) << "; caustics off "
              << regionPsnr(off) << " dB, gather off " << regionPsnr(gatherOff)
              << " dB, IOR 1.7 for 1.5 " << regionPsnr(ior) << " dB; caustic flux " << fluxRatio
              << " x the reference's\n";
    EXPECT_GE(regionPsnr(on), kRegionPsnr);
    EXPECT_NEAR(fluxRatio, 1.0, kFluxTolerance);
    EXPECT_LT(regionPsnr(off), kRegionPsnr);        // must-fail: caustics off
    EXPECT_LT(regionPsnr(gatherOff), kRegionPsnr);  // must-fail: the gather off
    EXPECT_LT(regionPsnr(ior), kRegionPsnr);        // must-fail: IOR 1.7 for 1.5
    EXPECT_FALSE(gatherOff.report.ran("photongrid"));
}

}  // namespace
}  // namespace mirage::render
