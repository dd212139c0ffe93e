// Temporal smoothing of the caustic buffer (Knecht 2013 end of Sec. 4.2; RendererOptions::
// causticTemporal, render/passes/caustic/caustic_resolve.frag): the caustic scene (a virtual glass
// sphere over a real table under a real spot light) seen by a camera whose pose jitters like a
// tracked one (0.5 mm, 0.05 degrees per frame). Judged: the caustic's frame-to-frame variation with
// smoothing on and off (the must-fail: off fails the floor); the composite against the Embree
// reference (caustics on) over a static and a jittered sequence, smoothed not worse than
// unsmoothed; the history reset rules shared with the GI filter (first frame, resetHistory, objects
// moved) giving exactly the frame of a renderer without history; a camera jump that does not
// smear; empty history texels and photons that leave the scene without NaN. docs/caustics.md has
// the figures.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <memory>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/image/ImageIO.h"
#include "core/scene/ScenePlacement.h"
#include "render/Renderer.h"
#include "render/evaluation/PoseJitter.h"
#include "render/passes/caustic/CausticPass.h"
#include "render/passes/specular/SpecularLightPass.h"
#include "tests/render/CausticReference.h"
#include "tests/support/HeadlessGlSuite.h"
#include "tests/support/TestSupport.h"
#include "testscenes/CausticTestScenes.h"

namespace mirage::render {
namespace {

class CausticTemporal : public test::HeadlessGlSuite {};

// Tracking noise of a camera standing still: 0.5 mm and 0.05 degrees (1 sigma), frame k's draw.
Pose jittered(const Pose& pose, int frame) {
    return jitteredPose(pose, 0.5, 0.05, uint64_t(frame) + 1);
}

// Which smoothing a test judges: the caustic buffer (CausticRv, seen directly) or the light of
// the reflected / refracted hits (SpecularRv, L'_rv: the caustic seen in a mirror).
enum class Judged { Caustic, Specular };

RendererOptions options(bool smoothing, Judged judged = Judged::Caustic) {
    RendererOptions o;
    (judged == Judged::Caustic ? o.caustic.temporal : o.specular.temporal) = smoothing;
    o.vpl.count = 64;
    return o;
}

// The caustic scene with the mirror, seen so that the table's caustic shows in the mirror.
test::CausticScene mirrorScene() {
    test::CausticSceneOptions o;
    o.mirror = true;
    test::CausticScene s = test::makeCausticScene(o);
    test::mirrorView(s, 128, 96, 176.0);
    return s;
}

std::string passReason(const FrameReport& r, const std::string& name) {
    for (const PassReport& p : r.passes)
        if (p.name == name) return p.reason;
    return "";
}

cv::Mat causticLuminance(const Renderer& r, Judged judged = Judged::Caustic) {
    const cv::Mat c = r.readBuffer(judged == Judged::Caustic ? kCausticRv : kSpecularRv);
    EXPECT_TRUE(cv::checkRange(c)) << "NaN/Inf in the judged buffer";
    return test::linearLuminance(c);
}

// A renderer without history at `pose`: its caustic's luminance, peak and region (above a
// tenth of the peak).
struct FreshCaustic {
    cv::Mat luminance, region;
    double peak = 0.0;
};

FreshCaustic freshCaustic(const test::CausticScene& s, const Pose& pose) {
    Renderer fresh(s.scene, s.cam, options(true));
    fresh.render({pose, cv::Mat(), true});
    FreshCaustic f;
    f.luminance = causticLuminance(fresh);
    cv::minMaxLoc(f.luminance, nullptr, &f.peak);
    f.region = f.luminance > 0.1 * f.peak;
    return f;
}

// The caustic's frame-to-frame variation over a jittered static view: frames [warmUp, frames)
// of a renderer that renders every frame, as the per-pixel temporal standard deviation of the
// caustic's luminance relative to its temporal mean, averaged over the caustic (pixels whose
// mean is > 10 % of the brightest mean; the region comes from the unsmoothed run).
struct Shimmer {
    cv::Mat mean, stddev;  // CV_32F per pixel
};

Shimmer shimmer(const test::CausticScene& s, bool smoothing, int frames, int warmUp,
                Judged judged = Judged::Caustic) {
    Renderer r(s.scene, s.cam, options(smoothing, judged));
    cv::Mat sum = cv::Mat::zeros(s.cam.height, s.cam.width, CV_64F), sum2 = sum.clone();
    for (int k = 0; k < frames; ++k) {
        r.render({jittered(s.pose, k), cv::Mat(), k == 0});
        EXPECT_TRUE(cv::checkRange(r.compositeLinear()));
        if (k < warmUp) continue;
        cv::Mat y;
        causticLuminance(r, judged).convertTo(y, CV_64F);
        sum += y;
        sum2 += y.mul(y);
    }
    const double n = frames - warmUp;
    Shimmer out;
    cv::Mat mean = sum / n, var = cv::max(sum2 / n - mean.mul(mean), 0.0), sd;
    cv::sqrt(var, sd);
    mean.convertTo(out.mean, CV_32F);
    sd.convertTo(out.stddev, CV_32F);
    return out;
}

double relativeShimmer(const Shimmer& s, const cv::Mat& region) {
    return cv::mean(s.stddev, region)[0] / std::max(cv::mean(s.mean, region)[0], 1e-12);
}

// The floor a smoothed caustic meets under tracking noise: its luminance varies from frame to
// frame by less than this fraction of its mean (average over the caustic). Measured (llvmpipe):
// 0.127 smoothed, 0.166 unsmoothed over the 32 px of the focused caustic; much of what is left
// is the caustic's real sub-pixel motion under the jitter across its steep flanks.
constexpr double kMaxRelativeShimmer = 0.15;
// The same for L'_rv over the mirror's and the glass's pixels. Measured (llvmpipe): 0.117
// smoothed, 0.150 unsmoothed over 391 px.
constexpr double kMaxRelativeShimmerSpecular = 0.135;

TEST_F(CausticTemporal, JitteredCameraShimmersLessWithSmoothingAndOffFailsTheFloor) {
    const test::CausticScene s = test::makeCausticScene({});
    const int frames = 20, warmUp = 8;
    const Shimmer off = shimmer(s, false, frames, warmUp);
    const Shimmer on = shimmer(s, true, frames, warmUp);
    double peak = 0;
    cv::minMaxLoc(off.mean, nullptr, &peak);
    ASSERT_GT(peak, 0.0) << "no caustic in view";
    const cv::Mat region = off.mean > 0.1 * peak;
    const double relOff = relativeShimmer(off, region), relOn = relativeShimmer(on, region);
    std::cout << "[ caustic ] jittered view (0.5 mm, 0.05 deg), " << cv::countNonZero(region)
              << " caustic px: relative frame-to-frame std off " << relOff << ", on " << relOn
              << " (x" << relOff / std::max(relOn, 1e-12) << " less)\n";
    RecordProperty("relative_shimmer_off", std::to_string(relOff));
    RecordProperty("relative_shimmer_on", std::to_string(relOn));
    ASSERT_GT(cv::countNonZero(region), 20);
    // The caustic is the same light either way (smoothing keeps its level).
    EXPECT_NEAR(cv::mean(on.mean, region)[0] / cv::mean(off.mean, region)[0], 1.0, 0.05);
    EXPECT_LT(relOn, kMaxRelativeShimmer);
    EXPECT_GT(relOff, kMaxRelativeShimmer) << "must-fail: unsmoothed, the same floor fails";
    EXPECT_GT(relOff / relOn, 1.2);
}

TEST_F(CausticTemporal, JitteredMirrorShimmersLessWithSmoothingAndOffFailsTheFloor) {
    const test::CausticScene s = mirrorScene();
    const int frames = 20, warmUp = 8;
    const Shimmer off = shimmer(s, false, frames, warmUp, Judged::Specular);
    const Shimmer on = shimmer(s, true, frames, warmUp, Judged::Specular);
    double peak = 0;
    cv::minMaxLoc(off.mean, nullptr, &peak);
    ASSERT_GT(peak, 0.0) << "no mirror in view";
    // The mirror's and the sphere's pixels that show something lit.
    const cv::Mat region = off.mean > 0.05 * peak;
    const double relOff = relativeShimmer(off, region), relOn = relativeShimmer(on, region);
    std::cout << "[ mirror L' ] jittered view (0.5 mm, 0.05 deg), " << cv::countNonZero(region)
              << " specular px: relative frame-to-frame std of L'_rv off " << relOff << ", on "
              << relOn << " (x" << relOff / std::max(relOn, 1e-12) << " less)\n";
    RecordProperty("relative_shimmer_specular_off", std::to_string(relOff));
    RecordProperty("relative_shimmer_specular_on", std::to_string(relOn));
    ASSERT_GT(cv::countNonZero(region), 200);
    // The same light either way, summed over every specular pixel (a region chosen by the
    // unsmoothed mean would favour the pixels its noise made bright).
    const cv::Mat lit = (off.mean > 0.0f) | (on.mean > 0.0f);
    const double level = cv::mean(on.mean, lit)[0] / cv::mean(off.mean, lit)[0];
    std::cout << "[ mirror L' ] L'_rv summed over the specular pixels, smoothed / unsmoothed: "
              << level << "\n";
    EXPECT_NEAR(level, 1.0, 0.05);
    EXPECT_LT(relOn, kMaxRelativeShimmerSpecular);
    EXPECT_GT(relOff, kMaxRelativeShimmerSpecular) << "must-fail: unsmoothed, the floor fails";
    EXPECT_GT(relOff / relOn, 1.2);
}

// The composite against the Embree reference (caustics on) over `region`, for a static and a
// jittered sequence, smoothing on and off: no lag error, and no loss under tracking noise.
void compareWithReference(const test::CausticScene& s, const test::CausticReferenceRender& ref,
                          const cv::Mat& region, Judged judged, double staticFloorDb) {
    const int frames = 10;
    // Static: every frame at the exact pose; jittered: the reference stays at the exact pose.
    for (bool jitter : {false, true}) {
        double psnr[2] = {0, 0}, psnrLast[2] = {0, 0};
        for (bool smoothing : {false, true}) {
            Renderer r(s.scene, s.cam, options(smoothing, judged));
            double sum = 0;
            for (int k = 0; k < frames; ++k) {
                r.render({jitter ? jittered(s.pose, k) : s.pose, ref.footage, k == 0});
                const double p = test::psnr(r.compositeSrgb(), ref.compositeSrgb, 255.0, region);
                sum += p;
                psnrLast[smoothing] = p;
            }
            psnr[smoothing] = sum / frames;
        }
        std::cout << "[ " << (judged == Judged::Caustic ? "caustic" : "mirror L'") << " ] "
                  << (jitter ? "jittered" : "static") << " sequence of " << frames << " frames, "
                  << cv::countNonZero(region)
                  << " px, region PSNR against the reference (mean / last frame): off " << psnr[0]
                  << " / " << psnrLast[0] << " dB, on " << psnr[1] << " / " << psnrLast[1]
                  << " dB\n";
        // No lag error: a static view converges to the frame it would render alone.
        EXPECT_GT(psnrLast[1], psnrLast[0] - 0.1);
        EXPECT_GT(psnr[1], psnr[0] - 0.1);
        if (!jitter) {
            EXPECT_GT(psnrLast[1], staticFloorDb);
        }
    }
}

TEST_F(CausticTemporal, SmoothedCausticIsNoWorseAgainstTheReferenceThanUnsmoothed) {
    const test::CausticScene s = test::makeCausticScene({});
    const test::CausticReferenceRender ref = test::renderCausticReference(s, 16, 9);
    ASSERT_GT(cv::countNonZero(ref.region), 200);
    compareWithReference(s, ref, ref.region, Judged::Caustic, 24.0);
}

TEST_F(CausticTemporal, SmoothedMirrorLightIsNoWorseAgainstTheReferenceThanUnsmoothed) {
    const test::CausticScene s = mirrorScene();
    const test::CausticReferenceRender ref = test::renderCausticReference(s, 16, 11);
    // The caustic region seen in the mirror: the specular pixels (L'_rv > 0) of a single frame.
    Renderer one(s.scene, s.cam, options(false, Judged::Specular));
    one.render({s.pose, ref.footage, true});
    cv::Mat specular = causticLuminance(one, Judged::Specular) > 0.0f;
    cv::erode(specular, specular, cv::Mat());
    const cv::Mat region = ref.region & specular;
    ASSERT_GT(cv::countNonZero(region), 100);
    compareWithReference(s, ref, region, Judged::Specular, 16.5);
}

TEST_F(CausticTemporal, ResetRulesGiveTheFrameOfARendererWithoutHistory) {
    const test::CausticScene s = test::makeCausticScene({});
    const Pose last = jittered(s.pose, 7);
    Renderer fresh(s.scene, s.cam, options(true));
    EXPECT_NE(passReason(fresh.render({last, cv::Mat(), true}), "caustic")
                  .find("temporal history reset (first frame)"),
              std::string::npos);
    const cv::Mat expected = causticLuminance(fresh);
    double peak = 0;
    cv::minMaxLoc(expected, nullptr, &peak);
    ASSERT_GT(peak, 0.0);

    // resetHistory (a cut, a seek, tracking loss).
    Renderer live(s.scene, s.cam, options(true));
    for (int k = 0; k < 7; ++k) live.render({jittered(s.pose, k), cv::Mat(), k == 0});
    EXPECT_NE(passReason(live.lastReport(), "caustic").find("temporal history used"),
              std::string::npos)
        << passReason(live.lastReport(), "caustic");
    live.render({last, cv::Mat(), false});
    const cv::Mat smoothed = causticLuminance(live);
    live.render({last, cv::Mat(), true});
    EXPECT_NE(passReason(live.lastReport(), "caustic")
                  .find("temporal history reset (cut, seek or tracking loss)"),
              std::string::npos)
        << passReason(live.lastReport(), "caustic");
    const double resetErr = cv::norm(causticLuminance(live), expected, cv::NORM_INF) / peak;
    const double smoothedErr = cv::norm(smoothed, expected, cv::NORM_INF) / peak;
    std::cout << "[ caustic ] largest difference to a renderer without history, relative to the "
                 "peak: after resetHistory "
              << resetErr << "; with the history kept (the comparison can fail) " << smoothedErr
              << "\n";
    EXPECT_LT(resetErr, 1e-3);
    EXPECT_GT(smoothedErr, 1e-2) << "the history changes the frame, so the test can fail";

    // Smoothing off: the report says so, and no history is used.
    Renderer off(s.scene, s.cam, options(false));
    off.render({s.pose, cv::Mat(), true});
    off.render({last, cv::Mat(), false});
    EXPECT_NE(passReason(off.lastReport(), "caustic").find("reset (smoothing off)"),
              std::string::npos);
    EXPECT_LT(cv::norm(causticLuminance(off), expected, cv::NORM_INF) / peak, 1e-3);
}

// The resolve shades only the tiles the photons reached or where last frame's lit history can
// pass (CausticTiles.h); the rest keep 0. Over a camera that walks sideways and jitters,
// splatting every other frame (the frames between take the history alone), the caustic must be
// the frames of a resolve on every pixel. The must-fail: tiles without the history's loses the
// caustic of the frames that only reuse it.
TEST_F(CausticTemporal, TheTiledResolveGivesTheFramesOfAResolveOnEveryPixel) {
    const test::CausticScene s = test::makeCausticScene({});
    auto run = [&](bool everywhere, bool ignoreHistory) {
        RendererOptions o = options(true);
        o.caustic.refreshInterval = 2;
        o.caustic.resolveEverywhere = everywhere;
        o.caustic.tilesIgnoreHistory = ignoreHistory;
        Renderer r(s.scene, s.cam, o);
        std::vector<cv::Mat> frames;
        for (int k = 0; k < 6; ++k) {
            Pose p = jittered(s.pose, k);
            p.translation.x += 0.004 * k;  // 4 mm a frame sideways
            r.render({p, cv::Mat(), k == 0});
            frames.push_back(r.readBuffer(kCausticRv));
            EXPECT_TRUE(cv::checkRange(frames.back()));
        }
        return frames;
    };
    const std::vector<cv::Mat> everywhere = run(true, false), tiled = run(false, false),
                               broken = run(false, true);
    double worst = 0.0, worstBroken = 0.0;
    for (size_t k = 0; k < everywhere.size(); ++k) {
        const cv::Mat want = test::linearLuminance(everywhere[k]);
        double peak = 0;
        cv::minMaxLoc(want, nullptr, &peak);
        ASSERT_GT(peak, 0.0) << "frame " << k << " has no caustic";
        worst =
            std::max(worst, cv::norm(test::linearLuminance(tiled[k]), want, cv::NORM_INF) / peak);
        worstBroken = std::max(
            worstBroken, cv::norm(test::linearLuminance(broken[k]), want, cv::NORM_INF) / peak);
    }
    std::cout << "[ caustic ] largest difference of the tiled resolve to the resolve on every "
                 "pixel, relative to the frame's peak: "
              << worst << "; with the history's tiles left out (must fail) " << worstBroken << "\n";
    EXPECT_LT(worst, 1e-3);
    EXPECT_GT(worstBroken, 0.5);
}

// The live loop renders one camera frame in several, and a hand-held camera turns by tens of
// degrees between them. A frame the refresh interval would let reuse the history splats when
// much of its view is new: a caustic that comes into view shows at once. The must-fail: reusing
// whatever the motion loses it until the next refresh.
TEST_F(CausticTemporal, ACausticComingIntoViewIsSplattedAtOnce) {
    const test::CausticScene s = test::makeCausticScene({});
    // From the same place, turned away from the sphere and its caustic.
    const Pose away = test::lookAtPose({-0.8, 0.6, 0.6}, {0.6, 0.05, 1.2});
    auto run = [&](float maxNewView, std::string& reason) {
        RendererOptions o = options(true);
        o.caustic.refreshInterval = 4;
        o.caustic.reuseMaxNewView = maxNewView;
        Renderer r(s.scene, s.cam, o);
        r.render({away, cv::Mat(), true});
        r.render({s.pose, cv::Mat(), false});
        reason = passReason(r.lastReport(), "caustic");
        return causticLuminance(r);
    };
    std::string reason, brokenReason;
    const cv::Mat guarded = run(0.02f, reason), broken = run(1.0f, brokenReason);
    const FreshCaustic want = freshCaustic(s, s.pose);
    ASSERT_GT(want.peak, 0.0);
    ASSERT_GT(cv::countNonZero(want.region), 20);
    const double expectedMean = cv::mean(want.luminance, want.region)[0];
    const double ratio = cv::mean(guarded, want.region)[0] / expectedMean;
    const double brokenRatio = cv::mean(broken, want.region)[0] / expectedMean;
    std::cout
        << "[ caustic ] turned towards the caustic in a frame that would reuse: caustic level "
        << "x" << ratio << " of a renderer without history (" << reason
        << "); reusing whatever the motion x" << brokenRatio << " (must fail)\n";
    EXPECT_NE(reason.find("% of the view new since last frame"), std::string::npos) << reason;
    EXPECT_NE(brokenReason.find("reprojected"), std::string::npos) << brokenReason;
    EXPECT_NEAR(ratio, 1.0, 0.05);
    EXPECT_LT(brokenRatio, 0.5);
}

TEST_F(CausticTemporal, MovedObjectsDropTheHistory) {
    const test::CausticScene s = test::makeCausticScene({});
    Scene moved = s.scene;
    ScenePlacement p;
    p.moveU = 0.03;
    ASSERT_GT(applyPlacement(moved, p, PlacementPlane{}), 0);

    Renderer live(s.scene, s.cam, options(true));
    for (int k = 0; k < 6; ++k) live.render({s.pose, cv::Mat(), k == 0});
    ASSERT_TRUE(live.updateTransforms(moved));
    live.render({s.pose, cv::Mat(), false});
    EXPECT_NE(passReason(live.lastReport(), "caustic").find("reset (objects moved)"),
              std::string::npos)
        << passReason(live.lastReport(), "caustic");
    const cv::Mat after = causticLuminance(live);

    Renderer fresh(moved, s.cam, options(true));
    fresh.render({s.pose, cv::Mat(), true});
    const cv::Mat expected = causticLuminance(fresh);
    Renderer before(s.scene, s.cam, options(true));
    before.render({s.pose, cv::Mat(), true});
    double peak = 0;
    cv::minMaxLoc(expected, nullptr, &peak);
    ASSERT_GT(peak, 0.0);
    const double err = cv::norm(after, expected, cv::NORM_INF) / peak;
    const double moveChanges = cv::norm(causticLuminance(before), expected, cv::NORM_INF) / peak;
    std::cout << "[ caustic ] after a 3 cm move: largest difference to a renderer built for the "
                 "moved scene "
              << err << " of the peak (the move itself changes it by " << moveChanges << ")\n";
    EXPECT_GT(moveChanges, 0.2);
    EXPECT_LT(err, 1e-3);
}

TEST_F(CausticTemporal, CameraJumpDoesNotSmear) {
    const test::CausticScene s = test::makeCausticScene({});
    // From the side the sphere hides another part of the table than from the start.
    const Pose jump = test::lookAtPose({-0.5, 0.55, -0.75}, {-0.1, 0.05, 0.0});
    Renderer live(s.scene, s.cam, options(true));
    for (int k = 0; k < 6; ++k) live.render({s.pose, cv::Mat(), k == 0});
    live.render({jump, cv::Mat(), false});
    const cv::Mat after = causticLuminance(live);
    // Where the view before the jump saw the same surface the history is the same caustic (it
    // is in the world); elsewhere (disoccluded, off the old view) it is rejected.
    const FreshCaustic want = freshCaustic(s, jump);
    ASSERT_GT(want.peak, 0.0);
    ASSERT_GT(cv::countNonZero(want.region), 20);
    const double scale = 255.0 / want.peak;
    const double psnr = test::psnr(after * scale, want.luminance * scale, 255.0);
    const double meanRatio =
        cv::mean(after, want.region)[0] / cv::mean(want.luminance, want.region)[0];
    std::cout << "[ caustic ] the frame after a camera jump against a renderer without history: "
              << "PSNR " << psnr << " dB (peak = the caustic's), caustic level x" << meanRatio
              << "\n";
    EXPECT_GT(psnr, 30.0);
    EXPECT_NEAR(meanRatio, 1.0, 0.05);
}

TEST_F(CausticTemporal, MirrorLightResetsWithTheSameRulesAndRejectsMovedHits) {
    const test::CausticScene s = mirrorScene();
    const Pose last = jittered(s.pose, 7);
    Renderer fresh(s.scene, s.cam, options(true, Judged::Specular));
    fresh.render({last, cv::Mat(), true});
    const cv::Mat expected = causticLuminance(fresh, Judged::Specular);
    double peak = 0;
    cv::minMaxLoc(expected, nullptr, &peak);
    ASSERT_GT(peak, 0.0);

    Renderer live(s.scene, s.cam, options(true, Judged::Specular));
    for (int k = 0; k < 7; ++k) live.render({jittered(s.pose, k), cv::Mat(), k == 0});
    EXPECT_NE(passReason(live.lastReport(), "speclight").find("temporal history used"),
              std::string::npos)
        << passReason(live.lastReport(), "speclight");
    live.render({last, cv::Mat(), false});
    const double smoothedErr =
        cv::norm(causticLuminance(live, Judged::Specular), expected, cv::NORM_INF) / peak;
    live.render({last, cv::Mat(), true});
    EXPECT_NE(passReason(live.lastReport(), "speclight")
                  .find("temporal history reset (cut, seek or tracking loss)"),
              std::string::npos);
    const double resetErr =
        cv::norm(causticLuminance(live, Judged::Specular), expected, cv::NORM_INF) / peak;
    std::cout << "[ mirror L' ] largest difference to a renderer without history, relative to "
                 "the peak: after resetHistory "
              << resetErr << "; with the history kept " << smoothedErr << "\n";
    EXPECT_LT(resetErr, 1e-3);
    EXPECT_GT(smoothedErr, 1e-2) << "the history changes the frame, so the test can fail";

    // A camera jump: the mirror seen from elsewhere reflects other things at other distances.
    const Pose jump = test::lookAtPose({-0.1, 0.3, 0.8}, {-0.2, 0.1, -0.3});
    live.render({jump, cv::Mat(), false});
    const cv::Mat after = causticLuminance(live, Judged::Specular);
    Renderer freshJump(s.scene, s.cam, options(true, Judged::Specular));
    freshJump.render({jump, cv::Mat(), true});
    const cv::Mat expectedJump = causticLuminance(freshJump, Judged::Specular);
    cv::minMaxLoc(expectedJump, nullptr, &peak);
    ASSERT_GT(peak, 0.0);
    const double psnr = test::psnr(after * (255.0 / peak), expectedJump * (255.0 / peak), 255.0);
    std::cout << "[ mirror L' ] the frame after a camera jump against a renderer without "
                 "history: PSNR "
              << psnr << " dB (peak = L'_rv's)\n";
    EXPECT_GT(psnr, 30.0);
}

TEST_F(CausticTemporal, EmptyHistoryAndPhotonsLeavingTheSceneStayFinite) {
    // Frame 0 looks at the sky (an empty history); frame 1 at the caustic: every history texel is
    // empty (camera distance 0) and rejected.
    test::CausticSceneOptions o;
    o.tableSize = 0.24f;  // most photons leave the scene past the table's edge
    const test::CausticScene s = test::makeCausticScene(o);
    const Pose sky = test::lookAtPose({-0.8, 0.6, 0.6}, {-2.0, 2.0, 2.0});
    Renderer live(s.scene, s.cam, options(true));
    live.render({sky, cv::Mat(), true});
    EXPECT_TRUE(cv::checkRange(live.compositeLinear()));
    for (int k = 0; k < 8; ++k) {
        live.render({jittered(s.pose, k), cv::Mat(), false});
        ASSERT_TRUE(cv::checkRange(live.compositeLinear())) << "frame " << k;
        causticLuminance(live);
    }
    Renderer fresh(s.scene, s.cam, options(false));
    fresh.render({jittered(s.pose, 7), cv::Mat(), true});
    const double total = cv::sum(causticLuminance(live))[0];
    const double totalFresh = cv::sum(causticLuminance(fresh))[0];
    std::cout << "[ caustic ] photons leaving the scene, jittered: smoothed total " << total
              << ", unsmoothed " << totalFresh << "\n";
    ASSERT_GT(totalFresh, 0.0);
    EXPECT_NEAR(total / totalFresh, 1.0, 0.1);
}

}  // namespace
}  // namespace mirage::render
