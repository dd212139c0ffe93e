// Fuzzy reflections of rough metals (render/passes/fuzzy, docs/specular.md) against the Embree
// reference renderer (GGX conductors): a virtual brushed-metal plate on a real table reflects a
// red box standing behind it and the sky. Over the plate's top face the real-time composite is
// compared with the reference differential composite (footage = the reference's real-only
// render as 8-bit sRGB) at three roughness values (0.15, 0.3, 0.5); the same render with the filter
// off (the roughness ignored: a sharp mirror image) must fall below the floor. Also: the filter in
// its roughness -> 0 limit equals the mirror path to the digit, it never changes a pixel outside
// the rough object, it runs only when the scene has a rough metal, and hard cases stay finite.
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
#include "tests/support/RenderMasks.h"
#include "tests/support/TestSupport.h"
#include "testscenes/RoughTestScenes.h"

namespace mirage::render {
namespace {

// The plate: a box whose top face (y = kTop) is the rough reflector.
constexpr float kTop = 0.04f;
const glm::vec3 kPlateLo{-0.35f, 0.0f, -0.25f}, kPlateHi{0.35f, kTop, 0.3f};

using PlateScene = test::RoughTestScene;
using Frame = test::RoughFrame;

PlateScene makePlate(float roughness, const std::filesystem::path& envDir,
                     Origin plateOrigin = Origin::Virtual) {
    PlateScene s;
    const int table = test::addMaterial(s.scene, glm::vec3(0.6f, 0.55f, 0.5f));
    const int red = test::addMaterial(s.scene, glm::vec3(0.8f, 0.15f, 0.1f));
    s.material = test::addMaterial(s.scene, glm::vec3(0.9f, 0.85f, 0.8f), roughness, 1.0f);
    test::addFloor(s.scene, "table", 0.0f, 3.0f, table, Origin::Real);
    test::addBox(s.scene, "plate", kPlateLo, kPlateHi, s.material, plateOrigin);
    // Behind the plate: its reflection has a sharp red / sky edge for the roughness to blur.
    test::addBox(s.scene, "red box", {-0.12f, 0.0f, -0.55f}, {0.12f, 0.3f, -0.4f}, red,
                 Origin::Real);
    const glm::vec3 lightPos(0.6f, 1.4f, 0.5f);
    test::addLight(s.scene, Light::Type::Spot, lightPos,
                   glm::normalize(glm::vec3(-0.3f, 0.0f, -0.6f) - lightPos), 3.0f, Origin::Real,
                   1.0f, 0.8f);
    test::addSkyEnvironment(s.scene, envDir);
    return s;
}

// Pixels whose camera ray meets the plate's top face with x in (xLo, xHi) (world, metres), 1 px
// in from its outline (the silhouette is mixed in the reference).
cv::Mat topMask(const PlateScene& s, double xLo = kPlateLo.x, double xHi = kPlateHi.x) {
    cv::Mat m(s.cam.height, s.cam.width, CV_8U, cv::Scalar(0));
    const Pose inv = s.pose;  // T_world_camera
    const glm::dvec3 eye = inv * glm::dvec3(0.0);
    for (int y = 0; y < m.rows; ++y)
        for (int x = 0; x < m.cols; ++x) {
            const glm::dvec3 dirCam((x - s.cam.cx) / s.cam.fx, (y - s.cam.cy) / s.cam.fy, 1.0);
            const glm::dvec3 d = inv * dirCam - eye;
            if (d.y >= 0) continue;
            const double t = (kTop - eye.y) / d.y;
            const glm::dvec3 p = eye + t * d;
            if (p.x > xLo && p.x < xHi && p.z > kPlateLo.z && p.z < kPlateHi.z)
                m.at<uint8_t>(y, x) = 255;
        }
    cv::erode(m, m, cv::Mat::ones(3, 3, CV_8U));
    return m;
}

RendererOptions singleFrame() {
    return test::roughSingleFrame();
}

test::RoughReference reference(const PlateScene& s) {
    return test::roughReference(s);
}

Frame realtime(const PlateScene& s, const cv::Mat& footage, RendererOptions opt = singleFrame()) {
    return test::renderRough(s, footage, opt);
}

void save(const std::string& name, const cv::Mat& footage, const cv::Mat& sharp,
          const cv::Mat& fuzzy, const cv::Mat& ref) {
    const auto dir = std::filesystem::path(MIRAGE_TEST_OUTPUT_DIR) / "fuzzy";
    std::filesystem::create_directories(dir);
    cv::Mat side;
    cv::hconcat(std::vector<cv::Mat>{footage, sharp, fuzzy, ref}, side);
    cv::resize(side, side, cv::Size(), 3.0, 3.0, cv::INTER_NEAREST);
    writeBgr8(dir / (name + ".png"), side);
}

// Floors over the plate's top face (measured: docs/specular.md, "Fuzzy reflections").
struct Floor {
    float roughness;
    double psnr, ssim;
};

TEST(FuzzyReflection, RoughMetalMatchesReferenceAndIgnoringRoughnessFails) {
    gl::Context context = gl::Context::headless();
    const auto envDir = test::outputDir("fuzzy_env");
    // Measured (llvmpipe; reference 64 spp, seed 5): 0.15: 35.8 dB / 0.954 with the filter, 33.2
    // dB ignored; 0.3: 33.8 dB / 0.881, 26.8 dB ignored; 0.5 (the filter's upper end): 28.4 dB /
    // 0.778, 22.5 dB ignored. Floors ~1.3-1.8 dB / 0.025 below.
    for (const Floor& fl :
         {Floor{0.15f, 34.5, 0.93}, Floor{0.3f, 32.0, 0.855}, Floor{0.5f, 27.0, 0.75}}) {
        const PlateScene s = makePlate(fl.roughness, envDir);
        const cv::Mat mask = topMask(s);
        ASSERT_GT(cv::countNonZero(mask), 1500);
        const test::RoughReference ref = reference(s);
        const Frame fuzzy = realtime(s, ref.footage);
        EXPECT_TRUE(fuzzy.report.ran("fuzzy")) << fuzzy.report.summary();
        RendererOptions off = singleFrame();
        off.fuzzy.enabled = false;
        const Frame sharp = realtime(s, ref.footage, off);
        EXPECT_FALSE(sharp.report.ran("fuzzy"));
        const double pF = test::psnr(fuzzy.srgb, ref.refSrgb, 255.0, mask);
        const double sF = test::ssim(fuzzy.srgb, ref.refSrgb, 255.0, mask);
        const double pS = test::psnr(sharp.srgb, ref.refSrgb, 255.0, mask);
        const double sS = test::ssim(sharp.srgb, ref.refSrgb, 255.0, mask);
        std::cout << "[ fuzzy ] roughness " << fl.roughness << ": filter PSNR " << pF << " dB SSIM "
                  << sF << "; roughness ignored PSNR " << pS << " dB SSIM " << sS << " over "
                  << cv::countNonZero(mask) << " px\n";
        save("plate_r" + std::to_string(int(fl.roughness * 100)), ref.footage, sharp.srgb,
             fuzzy.srgb, ref.refSrgb);
        EXPECT_GE(pF, fl.psnr);
        EXPECT_GE(sF, fl.ssim);
        EXPECT_LT(pS, fl.psnr);  // the must-fail: the sharp mirror image
    }
}

// Rough glass: a virtual frosted slab (tests/support/testscenes/RoughTestScenes.h) on the real
// table in front of a real red and green box; what is seen through it is blurred by the same
// filter with the refracted geometry (rough_method=filter; the default, LEAN, is tested in
// RoughRefraction_test.cpp). Compared over the slab's front face against the reference's GGX
// dielectric.
RendererOptions filterGlass(RendererOptions o = singleFrame()) {
    o.rough.method = RoughRefractionMethod::Filter;
    return o;
}

TEST(FuzzyReflection, RoughGlassMatchesReferenceAndIgnoringRoughnessFails) {
    gl::Context context = gl::Context::headless();
    const auto envDir = test::outputDir("fuzzy_env_glass");
    // Measured (llvmpipe; reference 64 spp, seed 5, its noise bounds the figures): 0.3: 25.6 dB
    // / 0.641 with the filter, 24.5 dB / 0.591 as smooth glass; 0.5: 25.1 dB / 0.530, 22.7 dB /
    // 0.450. Floors ~0.5-0.7 dB / 0.02 below.
    for (const Floor& fl : {Floor{0.3f, 25.1, 0.62}, Floor{0.5f, 24.4, 0.51}}) {
        const PlateScene s = test::makeRoughSlab(fl.roughness, envDir);
        const cv::Mat mask = test::slabFrontMask(s);
        ASSERT_GT(cv::countNonZero(mask), 1500);
        const test::RoughReference ref = reference(s);
        const Frame fuzzy = realtime(s, ref.footage, filterGlass());
        EXPECT_TRUE(fuzzy.report.ran("fuzzy")) << fuzzy.report.summary();
        RendererOptions off = filterGlass();
        off.fuzzy.enabled = false;
        const Frame sharp = realtime(s, ref.footage, off);
        const double pF = test::psnr(fuzzy.srgb, ref.refSrgb, 255.0, mask);
        const double sF = test::ssim(fuzzy.srgb, ref.refSrgb, 255.0, mask);
        const double pS = test::psnr(sharp.srgb, ref.refSrgb, 255.0, mask);
        const double sS = test::ssim(sharp.srgb, ref.refSrgb, 255.0, mask);
        std::cout << "[ fuzzy ] glass roughness " << fl.roughness << ": filter PSNR " << pF
                  << " dB SSIM " << sF << "; roughness ignored PSNR " << pS << " dB SSIM " << sS
                  << " over " << cv::countNonZero(mask) << " px\n";
        save("slab_r" + std::to_string(int(fl.roughness * 100)), ref.footage, sharp.srgb,
             fuzzy.srgb, ref.refSrgb);
        EXPECT_GE(pF, fl.psnr);
        EXPECT_GE(sF, fl.ssim);
        EXPECT_LT(pS, fl.psnr);  // the must-fail: smooth glass
    }
}

// The filter's one-pixel limit is the mirror path, to the digit: a metal just above the mirror
// threshold (roughness 0.051) goes through the fuzzy pass (resolve, both filter directions, the
// composite's fuzzy branch) and must composite exactly as the same metal at roughness 0, which is
// a perfect mirror and skips the pass. Also: no pixel outside the rough object changes when the
// filter runs (it never reaches across the silhouette), and the pass runs only with a rough metal.
TEST(FuzzyReflection, RoughnessZeroLimitEqualsMirrorPathAndOnlyTheObjectChanges) {
    gl::Context context = gl::Context::headless();
    const auto envDir = test::outputDir("fuzzy_env_limit");
    cv::Mat footage(96, 128, CV_8UC3);
    cv::randu(footage, 0, 255);
    const PlateScene mirror = makePlate(0.0f, envDir);
    const PlateScene limit = makePlate(0.051f, envDir);
    ASSERT_TRUE(limit.scene.materials[size_t(limit.material)].isRoughReflector());
    ASSERT_TRUE(mirror.scene.materials[size_t(mirror.material)].isMirror());
    // Without VPLs: the plate's roughness changes the light it bounces onto the table (the
    // reflective shadow map's flux), which is not the filter's business.
    RendererOptions noVpl = singleFrame();
    noVpl.vpl.count = 0;
    // The spot's GGX highlight on a rough metal (direct.roughHighlight) is light the mirror's
    // delta lobe shows only as a point the renderer cannot draw: not the filter's business.
    noVpl.direct.roughHighlight = false;
    const Frame a = realtime(mirror, footage, noVpl);
    // The kernel of one pixel: at this camera (120 px per radian) 2.5 sigma of roughness 0.051
    // still reaches 1.1 px, so the cone bound (0.3 deg: 0.6 px) makes the limit.
    noVpl.fuzzy.coneDeg = 0.3f;
    const Frame b = realtime(limit, footage, noVpl);
    EXPECT_FALSE(a.report.ran("fuzzy"));
    EXPECT_NE(a.report.summary().find("no rough metal"), std::string::npos) << a.report.summary();
    EXPECT_TRUE(b.report.ran("fuzzy")) << b.report.summary();
    EXPECT_EQ(cv::norm(a.linear, b.linear, cv::NORM_INF), 0.0);

    // Roughness 0.3: the filter changes the plate's pixels and nothing else.
    const PlateScene rough = makePlate(0.3f, envDir);
    const Frame on = realtime(rough, footage);
    RendererOptions offOpt = singleFrame();
    offOpt.fuzzy.enabled = false;
    const Frame off = realtime(rough, footage, offOpt);
    EXPECT_NE(off.report.summary().find("fuzzy filter off"), std::string::npos);
    const cv::Mat changed = test::changedPixels(on.linear, off.linear);
    // The plate (top and sides), 1 px dilated for the composite's rounding to canvas pixels.
    const cv::Mat plate = test::boxSilhouette(rough.cam, rough.pose, kPlateLo, kPlateHi);
    EXPECT_GT(cv::countNonZero(changed & plate), 200);  // the filter does something
    EXPECT_EQ(cv::countNonZero(changed & ~plate), 0);   // and only on the plate
}

// A rough REAL plate: the video already shows its real, blurred reflection, so the filter may only
// blur what the virtual objects change in it (Delta L' = L'_rv - L'_r, Eqs. 6-11). A virtual box
// beside the real red box is reflected in the plate's right half: with the filter on, its
// reflection spreads over more plate pixels than the sharp one, and the plate's left half, which
// reflects only real things, is the footage exactly (no VPLs, whose bounce off the virtual box
// would change every real pixel a little).
TEST(FuzzyReflection, RoughRealPlateBlursOnlyTheVirtualReflection) {
    gl::Context context = gl::Context::headless();
    const auto envDir = test::outputDir("fuzzy_env_real");
    cv::Mat footage(96, 128, CV_8UC3);
    cv::randu(footage, 0, 255);
    PlateScene s = makePlate(0.3f, envDir, Origin::Real);
    const int green = test::addMaterial(s.scene, glm::vec3(0.15f, 0.7f, 0.2f));
    test::addBox(s.scene, "virtual box", {0.16f, 0.0f, -0.55f}, {0.3f, 0.25f, -0.4f}, green,
                 Origin::Virtual);
    RendererOptions on = singleFrame();
    on.vpl.count = 0;
    RendererOptions off = on;
    off.fuzzy.enabled = false;
    const Frame blurred = realtime(s, footage, on), sharp = realtime(s, footage, off);
    EXPECT_TRUE(blurred.report.ran("fuzzy")) << blurred.report.summary();
    const cv::Mat plate = topMask(s), leftHalf = topMask(s, kPlateLo.x, -0.05);
    // Plate pixels whose 8-bit composite differs from the footage by more than one level.
    auto changed = [&](const cv::Mat& srgb) {
        cv::Mat d;
        cv::absdiff(srgb, footage, d);
        cv::Mat m;
        cv::transform(d, m, cv::Matx13f(1, 1, 1));
        return cv::countNonZero((m > 1.5) & plate);
    };
    const int changedOn = changed(blurred.srgb), changedOff = changed(sharp.srgb);
    const double leftError = cv::norm(blurred.srgb, footage, cv::NORM_INF, leftHalf);
    std::cout << "[ fuzzy ] real plate: " << changedOff << " plate px show the virtual box sharp, "
              << changedOn << " blurred; left half max |composite - footage| " << leftError
              << " (8-bit)\n";
    save("real_plate", footage, sharp.srgb, blurred.srgb, footage);
    EXPECT_GT(changedOff, 20);
    EXPECT_GT(changedOn, changedOff + 20);
    EXPECT_EQ(leftError, 0.0);
}

// Roughness varying across a rough metal: the plate's metallicRoughness texture (64x1, linear)
// has G = `left` on its left half and `right` on its right (factor 0.3), read per pixel by the
// G-buffer and by the filter. The texture spans u = 0.25 .. 0.75 over the plate (clear of the
// repeat wrap's blend at u = 0 / 1), so its bilinear seam is one texel = 11 mm wide (about 1.3 px
// here) about x = 0.
PlateScene texturedPlate(const std::filesystem::path& envDir, unsigned char left,
                         unsigned char right) {
    PlateScene s = makePlate(0.3f, envDir);
    Texture t;
    t.name = "half rough";
    t.width = 64;
    t.height = 1;
    t.srgb = false;
    for (int x = 0; x < t.width; ++x) {
        const unsigned char g = x < t.width / 2 ? left : right;
        t.pixels.insert(t.pixels.end(), {0, g, 0, 255});
    }
    s.scene.textures.push_back(t);
    s.scene.materials[size_t(s.material)].metallicRoughnessTexture.texture =
        int(s.scene.textures.size()) - 1;
    for (Mesh& m : s.scene.meshes) {
        if (m.name != "plate") continue;
        for (Primitive& p : m.primitives) {
            p.uv0.clear();
            for (const glm::vec3& v : p.positions)
                p.uv0.emplace_back(0.25f + 0.5f * (v.x - kPlateLo.x) / (kPlateHi.x - kPlateLo.x),
                                   0.5f);
        }
    }
    return s;
}

// The filter follows the per-pixel roughness: with the plate half smooth (G = 0: roughness 0.02
// after the G-buffer's floor) and half rough (G = 1: 0.3), every smooth-half pixel more than
// kBleedPx beyond the seam's ramp equals the sharp mirror render (the same plate, filter off) to
// the digit, and the rough half is blurred exactly as the all-rough plate (G = 1 everywhere,
// which is also the texture ignored). The must-fail: the texture ignored blurs the smooth half.
TEST(FuzzyReflection, HalfRoughTextureSmoothHalfStaysSharp) {
    gl::Context context = gl::Context::headless();
    const auto envDir = test::outputDir("fuzzy_env_half");
    const PlateScene s = texturedPlate(envDir, 0, 255);
    // Footage: the reference's real-only render (16 spp: only its look matters here).
    const cv::Mat footage = test::roughReference(s, 16).footage;
    const Frame half = realtime(s, footage);
    RendererOptions off = singleFrame();
    off.fuzzy.enabled = false;
    const Frame sharp = realtime(s, footage, off);
    const Frame rough = realtime(texturedPlate(envDir, 255, 255), footage);  // = texture ignored
    EXPECT_TRUE(half.report.ran("fuzzy")) << half.report.summary();
    // The seam's bilinear ramp is x in +-11 mm; kBleedPx more on each side.
    constexpr int kBleedPx = 1;
    const cv::Mat horizontal = cv::Mat::ones(1, 2 * kBleedPx + 1, CV_8U);
    cv::Mat smoothZone, roughZone;
    cv::erode(topMask(s, kPlateLo.x, -0.011), smoothZone, horizontal);
    cv::erode(topMask(s, 0.011, kPlateHi.x), roughZone, horizontal);
    ASSERT_GT(cv::countNonZero(smoothZone), 800);
    ASSERT_GT(cv::countNonZero(roughZone), 800);
    const int smoothChanged =
        cv::countNonZero(test::changedPixels(half.linear, sharp.linear) & smoothZone);
    const int ignoredChanged =
        cv::countNonZero(test::changedPixels(rough.linear, sharp.linear) & smoothZone);
    const int roughBlurred =
        cv::countNonZero(test::changedPixels(half.linear, sharp.linear) & roughZone);
    const double roughAsAllRough = test::psnr(half.srgb, rough.srgb, 255.0, roughZone);
    std::cout << "[ fuzzy ] half-rough plate: " << smoothChanged << " of "
              << cv::countNonZero(smoothZone) << " smooth-half px differ from the sharp render "
              << "(texture ignored: " << ignoredChanged << "); rough half: " << roughBlurred
              << " of " << cv::countNonZero(roughZone) << " px blurred, " << roughAsAllRough
              << " dB against the all-rough plate\n";
    save("half_rough", footage, sharp.srgb, half.srgb, rough.srgb);
    EXPECT_EQ(smoothChanged, 0) << "smooth-half pixels blurred";
    EXPECT_GT(roughBlurred, cv::countNonZero(roughZone) / 2) << "the rough half is not blurred";
    EXPECT_GE(roughAsAllRough, 40.0);
    // The must-fail: the texture ignored (the whole plate at the factor's roughness).
    EXPECT_GT(ignoredChanged, cv::countNonZero(smoothZone) / 2);
}

// Hard cases: roughness 1 (beyond the filter's range: the glossy path, no fuzzy pass), a
// grazing view over a rough plate, and a rough plate that fills the image past its edges (its
// reflection of things outside the image falls back to the rendered radiance); rough glass at
// roughness 1 and at a grazing view with total internal reflection: every buffer finite.
TEST(FuzzyReflection, HardCasesStayFinite) {
    gl::Context context = gl::Context::headless();
    const auto envDir = test::outputDir("fuzzy_env_hard");
    cv::Mat footage(96, 128, CV_8UC3, cv::Scalar(90, 110, 130));
    {
        PlateScene s = makePlate(1.0f, envDir);
        EXPECT_FALSE(s.scene.materials[size_t(s.material)].isRoughReflector());
        const Frame f = realtime(s, footage);
        EXPECT_FALSE(f.report.ran("fuzzy"));
        EXPECT_FALSE(f.report.ran("specgbuf"));  // a glossy surface, not a specular object
    }
    for (const Pose& pose :
         {test::lookAtPose({0.0, 0.06, 0.9}, {0.0, 0.04, -0.3}),      // grazing, 1.3 deg
          test::lookAtPose({0.0, 0.12, 0.05}, {0.0, 0.0, -0.05})}) {  // up close: past the edges
        for (float roughness : {0.06f, 0.3f, 0.5f}) {
            PlateScene s = makePlate(roughness, envDir);
            s.pose = pose;
            RendererOptions o = singleFrame();
            o.fuzzy.coneDeg = 60.0f;  // the widest cone: the longest kernels
            const Frame f = realtime(s, footage, o);
            EXPECT_TRUE(f.report.ran("fuzzy")) << f.report.summary();
            EXPECT_LT(cv::norm(f.linear, cv::NORM_INF), 10.0);
        }
    }
    // Rough glass at roughness 1 and seen at grazing angles through its 6 cm block, where the
    // refracted rays meet the side faces under total internal reflection.
    for (const Pose& pose : {test::lookAtPose({0.0, 0.25, 0.8}, {0.0, 0.12, -0.1}),
                             test::lookAtPose({0.7, 0.15, 0.05}, {0.0, 0.15, 0.0})}) {
        for (float roughness : {0.3f, 1.0f}) {
            PlateScene s = test::makeRoughSlab(roughness, envDir);
            s.pose = pose;
            const Frame f = realtime(s, footage, filterGlass());
            EXPECT_TRUE(f.report.ran("fuzzy")) << f.report.summary();
            EXPECT_LT(cv::norm(f.linear, cv::NORM_INF), 10.0);
        }
    }
}

}  // namespace
}  // namespace mirage::render
