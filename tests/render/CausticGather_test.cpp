// Caustics seen in reflections (docs/caustics.md, "Caustics seen in reflections and
// refractions"): the glass sphere's caustic on the table, seen in a virtual mirror, against the
// Embree reference with caustics ON. The camera-space caustic buffer cannot hold it (the camera
// does not see the point the mirror shows); the photon grid gathered at the mirror's reflected
// hits must. Compared over the mirror pixels where the reference's caustic adds > 5 % to L_rv;
// must-fail: the gather off. Hard cases: reflected hits with no photon in range and hits leaving
// the scene (finite, nothing added), a caustic focused to a few pixels (no firefly).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/gl/Context.h"
#include "core/image/ImageIO.h"
#include "render/Renderer.h"
#include "render/passes/specular/SpecularLightPass.h"
#include "render/raytrace/DifferentialRendering.h"
#include "render/raytrace/EmbreeDevice.h"
#include "tests/render/CausticReference.h"
#include "tests/support/TestSupport.h"
#include "testscenes/CausticTestScenes.h"

namespace mirage::render {
namespace {

using test::linearLuminance;

// Pixels that see the mirror's front (not the sphere), 1 px in from its outline. CV_8U 255 / 0.
cv::Mat mirrorMask(const test::CausticScene& s) {
    cv::Mat m(s.cam.height, s.cam.width, CV_8U, cv::Scalar(0));
    const glm::dvec3 eye = s.pose.translation;
    for (int y = 0; y < m.rows; ++y)
        for (int x = 0; x < m.cols; ++x) {
            const glm::dvec3 d =
                s.pose.rotation * glm::normalize(glm::dvec3((x - s.cam.cx) / s.cam.fx,
                                                            (y - s.cam.cy) / s.cam.fy, 1.0));
            const glm::dvec3 far = eye + 10.0 * d;
            if (!test::segmentHitsBox(eye, far, glm::dvec3(s.mirrorLo), glm::dvec3(s.mirrorHi)))
                continue;
            if (test::segmentNearPoint(eye, far, glm::dvec3(s.sphereCentre), s.sphereRadius + 0.01))
                continue;
            m.at<uint8_t>(y, x) = 255;
        }
    cv::erode(m, m, cv::Mat());
    return m;
}

// Does pixel (x, y)'s ray, reflected by the mirror's front (z = mirrorHi.z, facing +Z), leave the
// modelled scene (miss the 3 m table and the sphere)?
bool reflectionLeaves(const test::CausticScene& s, int x, int y) {
    const glm::dvec3 eye = s.pose.translation;
    const glm::dvec3 d =
        s.pose.rotation *
        glm::normalize(glm::dvec3((x - s.cam.cx) / s.cam.fx, (y - s.cam.cy) / s.cam.fy, 1.0));
    if (d.z >= 0) return false;
    const glm::dvec3 m = eye + d * ((double(s.mirrorHi.z) - eye.z) / d.z);
    const glm::dvec3 r(d.x, d.y, -d.z);
    if (test::segmentNearPoint(m, m + 10.0 * r, glm::dvec3(s.sphereCentre), s.sphereRadius + 0.02))
        return false;
    if (r.y >= 0) return true;
    const glm::dvec3 t = m + r * (-m.y / r.y);
    return std::abs(t.x) > 1.5 || std::abs(t.z) > 1.5;
}

struct Reference {
    cv::Mat footage;        // 8-bit sRGB BGR: L_r as footage
    cv::Mat compositeSrgb;  // 8-bit sRGB BGR: the reference composite
    cv::Mat caustic;        // linear RGB: L_rv(caustics on) - L_rv(caustics off)
    cv::Mat mirror;         // CV_8U: the mirror's pixels
    cv::Mat region;         // CV_8U: mirror pixels where the caustic adds > 5 % to L_rv
};

Reference reference(const test::CausticScene& s, int spp) {
    const test::CausticReferenceRender ref = test::renderCausticReference(s, spp, 11);
    Reference r;
    r.footage = ref.footage;
    r.compositeSrgb = ref.compositeSrgb;
    r.caustic = ref.caustic;
    r.mirror = mirrorMask(s);
    // The camera-space caustic's region (CausticReference.h), here only in the mirror.
    r.region = ref.region & r.mirror;
    return r;
}

struct Realtime {
    cv::Mat composite;            // sRGB8 BGR
    cv::Mat specRv, specR, lenv;  // L'_rv, L'_r, L_env (linear RGB)
    FrameReport report;
};

Realtime realtime(const test::CausticScene& s, const cv::Mat& footage, bool gather,
                  RendererOptions opt = {}) {
    opt.temporalBlend = 0.0f;
    opt.caustic.gather = gather;
    Renderer r(s.scene, s.cam, opt);
    Realtime out;
    out.report = r.render({s.pose, footage, true});
    out.composite = r.compositeSrgb();
    EXPECT_TRUE(cv::checkRange(r.compositeLinear())) << "NaN/Inf in the composite";
    out.specRv = r.readBuffer(kSpecularRv);
    out.specR = r.readBuffer(kSpecularR);
    out.lenv = r.readBuffer(kLenv);
    for (const cv::Mat* m : {&out.specRv, &out.specR, &out.lenv})
        EXPECT_TRUE(cv::checkRange(*m)) << "NaN/Inf in the specular buffers";
    return out;
}

void save(const std::string& name, const Reference& ref, const Realtime& on, const Realtime& off) {
    const auto dir = std::filesystem::path(MIRAGE_TEST_OUTPUT_DIR) / "caustics";
    std::filesystem::create_directories(dir);
    cv::Mat region3, side;
    cv::cvtColor(ref.region, region3, cv::COLOR_GRAY2BGR);
    cv::hconcat(std::vector<cv::Mat>{off.composite, on.composite, ref.compositeSrgb, region3},
                side);
    cv::resize(side, side, cv::Size(), 3.0, 3.0, cv::INTER_NEAREST);
    writeBgr8(dir / (name + ".png"), side);
}

// The caustic seen in the mirror alone: L'_rv with the gather on minus off, over the mirror.
cv::Mat gatheredCaustic(const Realtime& on, const Realtime& off, const cv::Mat& mirror) {
    cv::Mat d = cv::Mat::zeros(on.specRv.size(), CV_32F);
    cv::Mat(cv::max(linearLuminance(on.specRv - off.specRv), 0.0f)).copyTo(d, mirror);
    return d;
}

cv::Mat masked(const cv::Mat& y, const cv::Mat& mask) {
    cv::Mat m = cv::Mat::zeros(y.size(), CV_32F);
    y.copyTo(m, mask);
    return m;
}

// Floor from measurement (llvmpipe; reference 16 spp, seed 11; docs/caustics.md): region
// 18.6 dB with the gather, 9.4 dB without.
constexpr double kRegionPsnr = 17.5;
// The capped gather's mean absolute departure from reading every photon, relative to the gathered
// flux, on the focused caustic: measured 0.005 with a cap of 256, 0.32 with a cap of 1.
constexpr double kMaxCapDeparture = 0.05;

TEST(CausticGather, CausticSeenInMirrorMatchesReferenceAndGatherOffFails) {
    gl::Context context = gl::Context::headless();
    test::CausticSceneOptions o;
    o.mirror = true;
    test::CausticScene s = test::makeCausticScene(o);
    test::mirrorView(s, 128, 96, 176.0);
    const Reference ref = reference(s, 16);
    const int regionPx = cv::countNonZero(ref.region);
    ASSERT_GT(regionPx, 20) << "the reference shows no caustic in the mirror";
    const Realtime on = realtime(s, ref.footage, true), off = realtime(s, ref.footage, false);
    save("gather_mirror", ref, on, off);
    ASSERT_TRUE(on.report.ran("photongrid")) << on.report.summary();
    EXPECT_FALSE(off.report.ran("photongrid"));
    const double psnrOn = test::psnr(on.composite, ref.compositeSrgb, 255.0, ref.region);
    const double psnrOff = test::psnr(off.composite, ref.compositeSrgb, 255.0, ref.region);
    const double fluxRatio = cv::sum(gatheredCaustic(on, off, ref.mirror))[0] /
                             cv::sum(masked(linearLuminance(ref.caustic), ref.mirror))[0];
    std::cout << "[ caustic gather ] mirror " << cv::countNonZero(ref.mirror) << " px, region "
              << regionPx << " px: PSNR " << psnrOn << " dB (gather off " << psnrOff
              << " dB); caustic flux seen in the mirror " << fluxRatio << " x the reference's\n";
    EXPECT_GE(psnrOn, kRegionPsnr);
    EXPECT_LT(psnrOff, kRegionPsnr);  // must-fail: the gather off
    EXPECT_NEAR(fluxRatio, 1.0, 0.25);

    // Hard cases in the same frame: reflected rays that leave the scene (the mirror's top
    // reflects the empty sky) and reflected hits with no photon in range get exactly nothing
    // from the gather (and no NaN: realtime() checks every buffer).
    int leaving = 0, noPhoton = 0, surface = 0;
    for (int y = 0; y < ref.mirror.rows; ++y)
        for (int x = 0; x < ref.mirror.cols; ++x) {
            if (!ref.mirror.at<uint8_t>(y, x)) continue;
            const bool same = on.specRv.at<cv::Vec3f>(y, x) == off.specRv.at<cv::Vec3f>(y, x) &&
                              on.specR.at<cv::Vec3f>(y, x) == off.specR.at<cv::Vec3f>(y, x);
            if (reflectionLeaves(s, x, y)) {
                ++leaving;
                EXPECT_TRUE(same) << "a reflected ray that left the scene gathered at " << x << ","
                                  << y;
            } else {
                ++surface;
                noPhoton += same ? 1 : 0;
            }
        }
    std::cout << "[ caustic gather ] mirror pixels: " << leaving << " reflect the sky, " << noPhoton
              << " of " << surface << " surface hits have no photon in range\n";
    EXPECT_GT(leaving, 100);
    EXPECT_GT(noPhoton, 100);
}

// The sphere raised so that the table lies at the ball lens's focus, its caustic focused to a few
// pixels, seen in the mirror at 96x72.
test::CausticScene focusedCausticInMirror() {
    test::CausticSceneOptions o;
    o.mirror = true;
    o.sphereCentre = glm::vec3(0.0f, 0.13f, 0.0f);
    o.lightPos = glm::vec3(0.5f, 0.996f, 0.0f);
    test::CausticScene s = test::makeCausticScene(o);
    test::mirrorView(s, 96, 72, 132.0);
    return s;
}

// A caustic focused to a few pixels (the table at the ball lens's focus), seen in the mirror:
// finite, and no firefly (the gathered caustic's 3x3-smoothed peak at most 2x the reference's,
// plus 2 % of the brightest directly lit surface).
TEST(CausticGather, FocusedCausticInMirrorHasNoFirefly) {
    gl::Context context = gl::Context::headless();
    const test::CausticScene s = focusedCausticInMirror();
    const Reference ref = reference(s, 12);
    const Realtime on = realtime(s, ref.footage, true), off = realtime(s, ref.footage, false);
    save("gather_mirror_focused", ref, on, off);
    ASSERT_TRUE(on.report.ran("photongrid")) << on.report.summary();
    double lit = 0;
    cv::minMaxLoc(linearLuminance(srgbBgr8ToLinearRgb(ref.footage)), nullptr, &lit);
    cv::Mat rt = gatheredCaustic(on, off, ref.mirror),
            rf = masked(linearLuminance(ref.caustic), ref.mirror);
    cv::blur(rt, rt, cv::Size(3, 3));
    cv::blur(rf, rf, cv::Size(3, 3));
    double peakRt = 0, peakRef = 0;
    cv::minMaxLoc(rt, nullptr, &peakRt);
    cv::minMaxLoc(rf, nullptr, &peakRef);
    std::cout << "[ caustic gather ] focused, seen in the mirror: peak " << peakRt << " (reference "
              << peakRef << "), lit peak " << lit << "\n";
    EXPECT_GT(peakRt, 0.0);
    EXPECT_LE(peakRt, 2.0 * peakRef + 0.02 * lit);
}

// The gather's per-bucket cap (the default) on the focused caustic, where most photons share a
// few grid cells: reading a full bucket's stratified subsample (weighted by count / read) must
// keep the gathered caustic of reading them all (flux, per-pixel difference, PSNR against the
// reference) while it reads a fraction of them. Must-fail: a cap of 1 photon per bucket departs
// from reading all by far more than the floor.
TEST(CausticGather, CappedBucketsKeepTheFocusedCausticAndACapOfOneFails) {
    gl::Context context = gl::Context::headless();
    const test::CausticScene s = focusedCausticInMirror();
    const Reference ref = reference(s, 12);
    RendererOptions all, capped, one;
    all.caustic.gatherCap = 0;
    ASSERT_GT(capped.caustic.gatherCap, 1) << "the gather's cap is on by default";
    one.caustic.gatherCap = 1;
    const Realtime off = realtime(s, ref.footage, false);
    const Realtime rAll = realtime(s, ref.footage, true, all);
    const Realtime rCapped = realtime(s, ref.footage, true, capped);
    const Realtime rOne = realtime(s, ref.footage, true, one);
    const cv::Mat gAll = gatheredCaustic(rAll, off, ref.mirror);
    const double fluxAll = cv::sum(gAll)[0];
    ASSERT_GT(fluxAll, 0.0) << "no caustic gathered in the mirror";
    // Mean absolute per-pixel difference from reading every photon, relative to the mean.
    const auto departure = [&](const Realtime& r) {
        return cv::norm(gatheredCaustic(r, off, ref.mirror), gAll, cv::NORM_L1) / fluxAll;
    };
    const double depCapped = departure(rCapped), depOne = departure(rOne);
    const double fluxCapped = cv::sum(gatheredCaustic(rCapped, off, ref.mirror))[0] / fluxAll;
    const double psnrAll = test::psnr(rAll.composite, ref.compositeSrgb, 255.0, ref.region);
    const double psnrCapped = test::psnr(rCapped.composite, ref.compositeSrgb, 255.0, ref.region);
    std::cout << "[ caustic gather ] focused, cap " << capped.caustic.gatherCap
              << ": departure from reading all " << depCapped << " (cap 1: " << depOne << "), flux "
              << fluxCapped << " x; region PSNR " << psnrCapped << " dB (all " << psnrAll
              << " dB)\n";
    // The cap must have engaged here, or the comparison proves nothing.
    EXPECT_GT(depCapped, 0.0) << "no bucket held more photons than the cap";
    EXPECT_LT(depCapped, kMaxCapDeparture);
    EXPECT_GT(depOne, kMaxCapDeparture) << "must-fail: one photon per bucket";
    EXPECT_NEAR(fluxCapped, 1.0, 0.05);
    EXPECT_GE(psnrCapped, psnrAll - 0.3);
}

// A capped frame is reproducible: renderers of the same frame gather the same caustic, because
// the photons a capped bucket gives are chosen by their photon-map texels, not by the order the
// grid's scatter (atomics on llvmpipe's threads) stored them in. Only the summation order of
// the photons read may differ (float rounding, ~1e-7 of the value). Must-fail: the stride over
// the scatter order, the gather's first cap, differed by up to 0.4 % of the peak between two
// renderers. llvmpipe runs 8 threads here (if the environment does not say otherwise) so that
// the scatter's order varies on a 2-core machine too.
TEST(CausticGather, CappedFrameIsReproducible) {
    setenv("LP_NUM_THREADS", "8", 0);
    gl::Context context = gl::Context::headless();
    const test::CausticScene s = focusedCausticInMirror();
    const cv::Mat footage(s.cam.height, s.cam.width, CV_8UC3, cv::Scalar(90, 90, 90));
    RendererOptions capped;
    ASSERT_GT(capped.caustic.gatherCap, 0) << "the gather's cap is on by default";
    const Realtime first = realtime(s, footage, true, capped);
    ASSERT_TRUE(first.report.ran("photongrid")) << first.report.summary();
    double peak = 0;
    cv::minMaxLoc(linearLuminance(first.specRv), nullptr, &peak);
    ASSERT_GT(peak, 0.0);
    double worst = 0;
    for (int run = 1; run < 5; ++run) {
        const Realtime again = realtime(s, footage, true, capped);
        worst = std::max(worst, cv::norm(again.specRv, first.specRv, cv::NORM_INF) / peak);
        worst = std::max(worst, cv::norm(again.specR, first.specR, cv::NORM_INF) / peak);
    }
    std::cout << "[ caustic gather ] cap " << capped.caustic.gatherCap
              << ": largest difference between 5 renderers of the same frame " << worst
              << " of the peak\n";
    EXPECT_LE(worst, 1e-5);
}

// Routing by Eqs. 12-14, as the camera's caustic: the caustic seen in the mirror always reaches
// L'_rv, and L'_r only when the light, the glass and the receiver (the table) are all real.
TEST(CausticGather, GatheredCausticReachesLrOnlyWhenLightObjectAndReceiverAreReal) {
    gl::Context context = gl::Context::headless();
    for (int bits : {7, 5, 3, 6}) {  // light, sphere, table real: RRR, RVR, VRR, RRV
        test::CausticSceneOptions o;
        o.mirror = true;
        o.lightReal = (bits & 4) != 0;
        o.sphereReal = (bits & 2) != 0;
        o.tableReal = (bits & 1) != 0;
        test::CausticScene s = test::makeCausticScene(o);
        test::mirrorView(s, 64, 48, 88.0);
        const cv::Mat none(s.cam.height, s.cam.width, CV_8UC3, cv::Scalar(0, 0, 0));
        const Realtime on = realtime(s, none, true), off = realtime(s, none, false);
        const double rv = cv::sum(linearLuminance(on.specRv - off.specRv))[0];
        const double lr = cv::sum(linearLuminance(on.specR - off.specR))[0];
        std::cout << "[ caustic gather ] light " << (o.lightReal ? "R" : "V") << ", glass "
                  << (o.sphereReal ? "R" : "V") << ", table " << (o.tableReal ? "R" : "V")
                  << ": caustic in L'_rv " << rv << ", in L'_r " << lr << "\n";
        EXPECT_GT(rv, 0.5);
        if (bits == 7)
            EXPECT_NEAR(lr, rv, 1e-2 * rv);
        else
            EXPECT_EQ(lr, 0.0);
    }
}

}  // namespace
}  // namespace mirage::render
