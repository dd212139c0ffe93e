// Specular objects against the Embree reference renderer: for combinations of REAL /
// VIRTUAL light, specular object, reflected object and refracted object (Knecht 2013 Fig. 2),
// the real-time composite over the specular object's pixels is compared with the reference
// differential composite (CI = the reference's real-only render as 8-bit sRGB footage). Also the
// per-effect figures (reflection only: a mirror; refraction only / both: glass) and a
// deliberately broken render that must fail the floor. docs/specular.md has the figures.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iostream>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/gl/Context.h"
#include "core/image/ImageIO.h"
#include "render/Renderer.h"
#include "render/passes/specular/SpecularGBufferPass.h"
#include "render/passes/specular/SpecularLightPass.h"
#include "render/raytrace/DifferentialRendering.h"
#include "render/raytrace/EmbreeDevice.h"
#include "tests/support/TestSupport.h"
#include "testscenes/ReferenceFrame.h"
#include "testscenes/SpecularTestScenes.h"

namespace mirage::render {
namespace {

struct Result {
    double psnr = 0, ssim = 0;
    cv::Mat rt, ref, footage;
};

struct Comparison {
    test::SpecularScene scene;
    cv::Mat footage, refSrgb, mask;
};

Comparison reference(const test::SpecularScene& s, int spp = 48) {
    Comparison c{s, {}, {}, test::sphereMask(s)};
    // Photon map on: light through glass as it is (docs/caustics.md).
    const test::ReferenceFrame f = test::renderReferenceFrame(s.scene, s.cam, s.pose, spp, 3, true);
    c.footage = f.footage;
    c.refSrgb = f.composite;
    return c;
}

Result realtime(const Comparison& c, const test::SpecularScene& rtScene, RendererOptions opt = {}) {
    opt.temporalBlend = 0.0f;
    Renderer r(rtScene.scene, rtScene.cam, opt);
    r.render({rtScene.pose, c.footage, true});
    Result out;
    out.rt = r.compositeSrgb();
    const cv::Mat lin = r.compositeLinear();
    EXPECT_TRUE(cv::checkRange(lin)) << "NaN/Inf in the composite";
    out.psnr = test::psnr(out.rt, c.refSrgb, 255.0, c.mask);
    out.ssim = test::ssim(out.rt, c.refSrgb, 255.0, c.mask);
    return out;
}

void save(const std::string& name, const Comparison& c, const Result& r) {
    // Not test::outputDir (which empties the folder): every case of the suite adds its image.
    static const std::filesystem::path dir = [] {
        const auto d = std::filesystem::path(MIRAGE_TEST_OUTPUT_DIR) / "specular";
        std::filesystem::create_directories(d);
        return d;
    }();
    cv::Mat side;
    cv::hconcat(std::vector<cv::Mat>{c.footage, r.rt, c.refSrgb}, side);
    cv::resize(side, side, cv::Size(), 3.0, 3.0, cv::INTER_NEAREST);
    writeBgr8(dir / (name + ".png"), side);
}

// Fig. 2 combinations (light, specular object, reflected object, refracted object; R = real,
// V = virtual): all 16, each against two reference renders (~1.4 s per case).
std::vector<test::SpecularCase> allFig2Cases() {
    std::vector<test::SpecularCase> cases;
    for (int bits = 0; bits < 16; ++bits)
        cases.push_back({(bits & 8) != 0, (bits & 4) != 0, (bits & 2) != 0, (bits & 1) != 0});
    return cases;
}

// Floors over the sphere's pixels, ~0.7 dB / 0.03 below the lowest measured case (23.2 dB, SSIM
// 0.600: virtual light, virtual glass, real surroundings; llvmpipe, reference 48 spp seed 3,
// caustics on); the broken render (IOR 1.2) scores 20.3 dB. docs/specular.md lists every case.
constexpr double kMinPsnr = 22.5, kMinSsim = 0.57;

class SpecularFig2 : public ::testing::TestWithParam<test::SpecularCase> {};

TEST_P(SpecularFig2, MatchesReferenceOverTheSpecularObject) {
    gl::Context context = gl::Context::headless();
    const test::SpecularCase k = GetParam();
    const auto s = test::makeSpecularScene(k, test::outputDir("specular_env_" + k.name()));
    const Comparison c = reference(s);
    const Result r = realtime(c, s);
    save(k.name(), c, r);
    std::cout << "[ specular ] " << k.name() << ": PSNR " << r.psnr << " dB, SSIM " << r.ssim
              << " over " << cv::countNonZero(c.mask) << " sphere pixels\n";
    RecordProperty("psnr_db", std::to_string(r.psnr));
    RecordProperty("ssim", std::to_string(r.ssim));
    EXPECT_GE(r.psnr, kMinPsnr);
    EXPECT_GE(r.ssim, kMinSsim);
}

INSTANTIATE_TEST_SUITE_P(Fig2, SpecularFig2, ::testing::ValuesIn(allFig2Cases()),
                         [](const auto& info) { return info.param.name(); });

// Per effect: reflection only (a mirror sphere), both (glass), refraction only (glass, the
// sphere's central disc where Fresnel reflection is < 5 %). The broken render (the real-time
// glass with IOR 1.2 instead of 1.5: wrong magnification) must fall below the floor.
TEST(SpecularAccuracy, PerEffectAndBrokenRenderFails) {
    gl::Context context = gl::Context::headless();
    test::SpecularCase k;  // real light, virtual object, real surroundings
    const auto envDir = test::outputDir("specular_env_effects");
    {
        const auto s = test::makeSpecularScene(k, envDir, test::SpecularKind::Mirror);
        const Comparison c = reference(s);
        const Result r = realtime(c, s);
        save("effect_reflection_mirror", c, r);
        std::cout << "[ specular ] reflection only (mirror): PSNR " << r.psnr << " dB, SSIM "
                  << r.ssim << "\n";
        EXPECT_GE(r.psnr, kMinPsnr);
        EXPECT_GE(r.ssim, kMinSsim);
    }
    const auto s = test::makeSpecularScene(k, envDir);
    Comparison c = reference(s);
    const Result both = realtime(c, s);
    std::cout << "[ specular ] both (glass): PSNR " << both.psnr << " dB, SSIM " << both.ssim
              << "\n";
    EXPECT_GE(both.psnr, kMinPsnr);
    EXPECT_GE(both.ssim, kMinSsim);
    {
        // The other interleaving: the default is 16 (4x4 tiles); 4 (2x2) must meet the floors too
        // and, summing 4x the VPLs per hit, be no worse than the default.
        RendererOptions o;
        o.specular.vplStride = 4;
        const Result dense = realtime(c, s, o);
        std::cout << "[ specular ] both (glass), specularVplStride 4: PSNR " << dense.psnr
                  << " dB, SSIM " << dense.ssim << "\n";
        EXPECT_GE(dense.psnr, kMinPsnr);
        EXPECT_GE(dense.ssim, kMinSsim);
        EXPECT_GE(dense.ssim, both.ssim - 0.005);
    }
    const cv::Mat full = c.mask.clone();
    c.mask = test::sphereMask(s, 0.4 * s.sphereRadius / glm::length(glm::vec3(0.0f, 0.35f, 1.1f)) *
                                     s.cam.fx);  // inner disc: radius ~60 %
    ASSERT_GT(cv::countNonZero(c.mask), 50);
    const Result refr = realtime(c, s);
    std::cout << "[ specular ] refraction only (glass centre): PSNR " << refr.psnr << " dB, SSIM "
              << refr.ssim << "\n";
    EXPECT_GE(refr.psnr, kMinPsnr);
    c.mask = full;
    const auto broken = test::makeSpecularScene(k, envDir, test::SpecularKind::Glass, 1.2f);
    const Result bad = realtime(c, broken);
    save("broken_ior_1_2", c, bad);
    std::cout << "[ specular ] broken (IOR 1.2 for 1.5): PSNR " << bad.psnr << " dB, SSIM "
              << bad.ssim << "\n";
    EXPECT_TRUE(bad.psnr < kMinPsnr || bad.ssim < kMinSsim);
    EXPECT_LT(bad.psnr, both.psnr - 3.0);
}

// L'_rv of the glass sphere's pixels whose reflected or refracted hit steps to another surface
// next to them (a 4-neighbour's hit normal more than 37 degrees off: the boxes' edges against
// the table seen in the sphere), for one renderer setting.
struct StepPixels {
    cv::Mat specRv, mask;
};

StepPixels specularAtHitSteps(const Comparison& c, const test::SpecularScene& s,
                              RendererOptions opt) {
    opt.temporalBlend = 0.0f;
    Renderer r(s.scene, s.cam, opt);
    r.render({s.pose, c.footage, true});
    StepPixels out{r.readBuffer(kSpecularRv), cv::Mat(c.mask.size(), CV_8U, cv::Scalar(0))};
    const cv::Mat hits[2] = {r.readBuffer(kReflectionNormal), r.readBuffer(kRefractionNormal)};
    for (int y = 1; y + 1 < c.mask.rows; ++y)
        for (int x = 1; x + 1 < c.mask.cols; ++x) {
            if (c.mask.at<uint8_t>(y, x) == 0) continue;
            for (const cv::Mat& h : hits)
                for (const cv::Point d :
                     {cv::Point(1, 0), cv::Point(-1, 0), cv::Point(0, 1), cv::Point(0, -1)}) {
                    const cv::Vec3f a = h.at<cv::Vec3f>(y, x),
                                    b = h.at<cv::Vec3f>(y + d.y, x + d.x);
                    if (c.mask.at<uint8_t>(y + d.y, x + d.x) != 0 && a.dot(b) < 0.8f)
                        out.mask.at<uint8_t>(y, x) = 255;
                }
        }
    return out;
}

// Half-resolution specular lighting (RendererOptions::specular.halfResolution) against the
// reference over the glass and the mirror sphere: within the floors, and within 0.5 dB of the
// full-resolution render over the glass sphere (2.5 dB over the small mirror sphere, see below).
// What keeps it there at depth steps is the upsample's geometry test: over the glass sphere's
// pixels whose hits step to another surface, L'_rv departs from the full-resolution L'_rv at
// least 1.5x as much without it (plain bilinear weights: the must-fail).
TEST(SpecularAccuracy, HalfResolutionLightingKeepsTheFloorsAndNeedsItsGeometryTest) {
    gl::Context context = gl::Context::headless();
    test::SpecularCase k;  // real light, virtual object, real surroundings
    const auto envDir = test::outputDir("specular_env_half");
    RendererOptions half;
    half.specular.halfResolution = true;
    for (const auto kind : {test::SpecularKind::Glass, test::SpecularKind::Mirror}) {
        const auto s = test::makeSpecularScene(k, envDir, kind);
        const Comparison c = reference(s);
        const Result full = realtime(c, s), halved = realtime(c, s, half);
        const char* what = kind == test::SpecularKind::Glass ? "glass" : "mirror";
        save(std::string("half_resolution_") + what, c, halved);
        std::cout << "[ specular ] " << what << ": full resolution PSNR " << full.psnr
                  << " dB, SSIM " << full.ssim << "; half resolution PSNR " << halved.psnr
                  << " dB, SSIM " << halved.ssim << "\n";
        EXPECT_GE(halved.psnr, kMinPsnr);
        EXPECT_GE(halved.ssim, kMinSsim);
        // The mirror sphere minifies the whole scene into ~30 px: half resolution halves that
        // again (measured -2.1 dB, SSIM -0.04); the glass sphere magnifies (-0.04 dB).
        const bool glass = kind == test::SpecularKind::Glass;
        EXPECT_GE(halved.psnr, full.psnr - (glass ? 0.5 : 2.5));
        EXPECT_GE(halved.ssim, full.ssim - (glass ? 0.03 : 0.06));
    }
    const auto s = test::makeSpecularScene(k, envDir);
    const Comparison c = reference(s);
    RendererOptions plain = half;
    plain.specular.upsampleGeometry = false;
    const StepPixels full = specularAtHitSteps(c, s, {});
    const StepPixels withGeometry = specularAtHitSteps(c, s, half);
    const StepPixels bilinear = specularAtHitSteps(c, s, plain);
    ASSERT_GT(cv::countNonZero(full.mask), 20);
    const double errGeometry = test::meanAbsDiff(withGeometry.specRv, full.specRv, full.mask);
    const double errBilinear = test::meanAbsDiff(bilinear.specRv, full.specRv, full.mask);
    std::cout << "[ specular ] half resolution at " << cv::countNonZero(full.mask)
              << " hit-step pixels: mean |L'_rv - full| " << errGeometry
              << " with the geometry test, " << errBilinear << " without\n";
    EXPECT_GT(errBilinear, 1.5 * errGeometry);
}

// The refracted path's second exit (SpecularOptions::secondExit): the share of the light the
// back face reflects inside leaves the sphere again, most of it on the rim, where the sharp path
// alone leaves the glass too dark. Over the rim (the sphere's outer 20 % of radius) the render
// with it must come closer to the reference by a margin and meet a floor the render without it
// misses (the must-fail); over the whole sphere it must not be worse.
TEST(SpecularAccuracy, SecondExitLightsTheGlassRim) {
    gl::Context context = gl::Context::headless();
    test::SpecularCase k;  // real light, virtual glass, real surroundings
    const auto s = test::makeSpecularScene(k, test::outputDir("specular_env_second_exit"));
    Comparison c = reference(s);
    RendererOptions off;
    off.specular.secondExit = false;
    const Result wholeOn = realtime(c, s), wholeOff = realtime(c, s, off);
    const cv::Mat inner = test::sphereMask(
        s, 0.53 * s.sphereRadius / glm::length(glm::vec3(0.0f, 0.35f, 1.1f)) * s.cam.fx);
    c.mask = c.mask & ~inner;
    ASSERT_GT(cv::countNonZero(c.mask), 100);
    const Result on = realtime(c, s), offRim = realtime(c, s, off);
    save("second_exit_rim_on", c, on);
    save("second_exit_rim_off", c, offRim);
    std::cout << "[ specular ] second exit over the rim (" << cv::countNonZero(c.mask)
              << " px): on " << on.psnr << " dB / " << on.ssim << ", off " << offRim.psnr
              << " dB / " << offRim.ssim << "; whole sphere on " << wholeOn.psnr << ", off "
              << wholeOff.psnr << " dB\n";
    // Measured (llvmpipe; reference 48 spp, seed 3): rim 28.46 dB on, 26.51 dB off; whole
    // sphere 28.72 / 27.02 dB.
    constexpr double kRimFloor = 27.9;
    EXPECT_GE(on.psnr, kRimFloor);
    EXPECT_LT(offRim.psnr, kRimFloor);  // the must-fail: the first exit alone
    EXPECT_GE(on.psnr, offRim.psnr + 1.0);
    EXPECT_GE(wholeOn.psnr, wholeOff.psnr);
}

}  // namespace
}  // namespace mirage::render
