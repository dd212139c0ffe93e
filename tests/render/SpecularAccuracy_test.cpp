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
#include "render/raytrace/DifferentialRendering.h"
#include "render/raytrace/EmbreeDevice.h"
#include "tests/support/TestSupport.h"
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
    const raytrace::EmbreeDevice device("threads=2");
    raytrace::RenderSettings st;
    st.samplesPerPixel = spp;
    st.threads = 2;
    st.seed = 3;
    st.caustics = true;  // photon map on: light through glass as it is (docs/caustics.md)
    const raytrace::DifferentialImages ref =
        raytrace::renderDifferential(s.scene, device, {s.cam, s.pose}, st);
    EXPECT_EQ(ref.realStats.nonFiniteSamples + ref.mixedStats.nonFiniteSamples, 0);
    c.footage = linearRgbToSrgbBgr8(ref.realOnly);
    c.refSrgb =
        linearRgbToSrgbBgr8(raytrace::compositeDifferential(srgbBgr8ToLinearRgb(c.footage), ref));
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
        RendererOptions o;
        o.specularVplStride = 16;  // the cheapest setting: VPLs at the hits interleaved 4x4
        const Result cheap = realtime(c, s, o);
        std::cout << "[ specular ] both (glass), specularVplStride 16: PSNR " << cheap.psnr
                  << " dB, SSIM " << cheap.ssim << "\n";
        EXPECT_GE(cheap.psnr, kMinPsnr);
        EXPECT_GE(cheap.ssim, kMinSsim);
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

}  // namespace
}  // namespace mirage::render
