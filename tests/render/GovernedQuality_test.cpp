// The quality settings a frame-time governor changes while the renderer runs (render/governor/):
// the caustic refreshed every N frames (CausticOptions::refreshInterval: last frame's caustic
// reprojected in the frames between) and the reflected / refracted rays traced at half
// resolution (SpecularOptions::halfResolutionTrace), each against the Embree reference of the
// caustic scene (a virtual glass sphere over a real table under a real spot light) on a moving
// camera and after a moving object, each with a must-fail; and Renderer::setQuality giving the
// frames of a renderer built with those options. docs/live.md, "Frame-time budget", has the
// figures.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/scene/ScenePlacement.h"
#include "render/Renderer.h"
#include "render/governor/GovernedKnobs.h"
#include "render/passes/caustic/CausticPass.h"
#include "tests/render/CausticReference.h"
#include "tests/support/HeadlessGlSuite.h"
#include "tests/support/TestSupport.h"
#include "testscenes/CausticTestScenes.h"
#include "testscenes/SpecularTestScenes.h"

namespace mirage::render {
namespace {

class GovernedQuality : public test::HeadlessGlSuite {};

RendererOptions options(const QualitySetting& setting = {}) {
    RendererOptions o;
    o.vpl.count = 64;
    applyQualitySetting(setting, o);
    return o;
}

// The camera panned sideways (world +X, eye and target together) by `cm` centimetres from the
// caustic scene's pose: the caustic moves across the image.
Pose pan(double cm) {
    const glm::dvec3 d(0.01 * cm, 0.0, 0.0);
    return test::lookAtPose(glm::dvec3(-0.8, 0.6, 0.6) + d, glm::dvec3(-0.1, 0.05, 0.0) + d);
}

// The camera orbiting the scene's target by `deg` degrees about +Y from the scene's pose.
Pose orbit(double deg) {
    const glm::dvec3 eye0(-0.8, 0.6, 0.6), target(-0.1, 0.05, 0.0);
    const double a = glm::radians(deg);
    const glm::dvec3 d = eye0 - target;
    const glm::dvec3 eye = target + glm::dvec3(std::cos(a) * d.x + std::sin(a) * d.z, d.y,
                                               -std::sin(a) * d.x + std::cos(a) * d.z);
    return test::lookAtPose(eye, target);
}

std::string passReason(const FrameReport& r, const std::string& name) {
    for (const PassReport& p : r.passes)
        if (p.name == name) return p.reason;
    return "";
}

cv::Mat causticLuminance(const Renderer& r) {
    return test::linearLuminance(r.readBuffer(kCausticRv));
}

// PSNR of two caustic luminance images with the fresh one's peak as 255.
double causticPsnr(const cv::Mat& got, const cv::Mat& expected) {
    double peak = 0;
    cv::minMaxLoc(expected, nullptr, &peak);
    return test::psnr(got * (255.0 / peak), expected * (255.0 / peak), 255.0);
}

// A moving camera (panned 1.5 cm per frame, 8 frames): the composite of the last frame, a
// reuse frame of caustic_refresh=4, against the Embree reference at that pose, as the caustic
// refreshed every frame. The must-fail: the caustic of the frame before, taken without
// reprojection, is far from the fresh one where the reprojected one is close.
TEST_F(GovernedQuality, CausticRefreshOnAMovingCameraAgainstTheReference) {
    test::CausticScene s = test::makeCausticScene({});
    const int frames = 8;
    const double step = 1.5;  // cm per frame
    s.pose = pan(step * (frames - 1));
    const test::CausticReferenceRender ref = test::renderCausticReference(s, 16, 21);
    ASSERT_GT(cv::countNonZero(ref.region), 200);
    double psnr[2] = {0, 0};
    cv::Mat previousCaustic, lastCaustic;
    for (int refresh : {1, 4}) {
        Renderer r(s.scene, s.cam, options({{"caustic_refresh", std::to_string(refresh)}}));
        for (int k = 0; k < frames; ++k) {
            if (k == frames - 1 && refresh == 4) previousCaustic = causticLuminance(r);
            const FrameReport& rep = r.render({pan(step * k), ref.footage, k == 0});
            const bool reused = passReason(rep, "caustic").find("reprojected") != std::string::npos;
            EXPECT_EQ(reused, refresh == 4 && k % 4 != 0) << "frame " << k;
        }
        psnr[refresh == 4] = test::psnr(r.compositeSrgb(), ref.compositeSrgb, 255.0, ref.region);
        if (refresh == 4) lastCaustic = causticLuminance(r);
    }
    Renderer fresh(s.scene, s.cam, options());
    fresh.render({s.pose, ref.footage, true});
    const cv::Mat expected = causticLuminance(fresh);
    const double reprojected = causticPsnr(lastCaustic, expected);
    const double stale = causticPsnr(previousCaustic, expected);
    std::cout << "[ caustic refresh ] moving camera (" << step << " cm/frame), caustic region "
              << cv::countNonZero(ref.region) << " px against the reference: every frame "
              << psnr[0] << " dB, every 4th frame " << psnr[1]
              << " dB; the reuse frame's caustic against a fresh one: reprojected " << reprojected
              << " dB, last frame's unreprojected " << stale << " dB\n";
    EXPECT_GT(psnr[1], psnr[0] - 1.0);
    EXPECT_GT(reprojected, 40.0);
    EXPECT_LT(stale, 40.0) << "must-fail: without reprojection the moved caustic is caught";
}

// A moving object drops the history: the frame after a move splats the photons whatever the
// refresh interval, and equals the frame of a renderer built for the moved scene.
TEST_F(GovernedQuality, CausticRefreshSplatsAfterAnObjectMoved) {
    const test::CausticScene s = test::makeCausticScene({});
    Scene moved = s.scene;
    ScenePlacement placement;
    placement.moveU = 0.03;  // 3 cm along the table
    ASSERT_GT(applyPlacement(moved, placement, PlacementPlane{}), 0);
    Renderer r(s.scene, s.cam, options({{"caustic_refresh", "8"}}));
    for (int k = 0; k < 3; ++k) r.render({s.pose, cv::Mat(), k == 0});
    ASSERT_TRUE(r.updateTransforms(moved));
    const FrameReport& rep = r.render({s.pose, cv::Mat(), false});
    EXPECT_EQ(passReason(rep, "caustic").find("reprojected"), std::string::npos)
        << passReason(rep, "caustic");
    Renderer fresh(moved, s.cam, options({{"caustic_refresh", "8"}}));
    fresh.render({s.pose, cv::Mat(), true});
    const double p = causticPsnr(causticLuminance(r), causticLuminance(fresh));
    std::cout << "[ caustic refresh ] the frame after a move against a renderer built moved: " << p
              << " dB\n";
    EXPECT_GT(p, 45.0);
}

// The rays traced at half resolution: the glass sphere's pixels (256x192) against the reference,
// within
// 1.5 dB of the full-resolution trace, on a moving camera (the last of 4 frames). The must-fail:
// the same comparison catches the cube-map baseline traced instead of the impostors.
TEST_F(GovernedQuality, HalfResolutionTraceAgainstTheReference) {
    test::CausticScene s = test::makeCausticScene({});
    s.cam = test::smallCamera(256, 192, 300.0);
    s.pose = orbit(6.0);
    const test::CausticReferenceRender ref = test::renderCausticReference(s, 16, 23);
    const cv::Mat sphere = test::sphereMask(test::sphereView(s), 0.98);
    ASSERT_GT(cv::countNonZero(sphere), 300);
    auto judge = [&](const QualitySetting& q, bool cubeMap = false) {
        RendererOptions o = options(q);
        o.impostor.cubeMapBaseline = cubeMap;
        Renderer r(s.scene, s.cam, o);
        for (int k = 0; k < 4; ++k) r.render({orbit(2.0 * k), ref.footage, k == 0});
        return test::psnr(r.compositeSrgb(), ref.compositeSrgb, 255.0, sphere);
    };
    const double full = judge({});
    const double half = judge({{"specular_trace_resolution", "half"}});
    const double halfBoth =
        judge({{"specular_trace_resolution", "half"}, {"specular_resolution", "half"}});
    const double unrefined = judge({}, true);
    std::cout << "[ half trace ] glass sphere, " << cv::countNonZero(sphere)
              << " px against the reference: full " << full << " dB, half trace " << half
              << " dB, half trace + half lighting " << halfBoth
              << " dB; the cube-map baseline instead of the impostors (must-fail) " << unrefined
              << " dB\n";
    // Inside a sphere 55 px wide a 2x2 block is the refraction's own detail: 1.3 dB measured.
    EXPECT_GT(half, full - 1.5);
    EXPECT_GT(halfBoth, full - 1.5);
    EXPECT_LT(unrefined, full - 1.5) << "must-fail: a worse trace is caught by the same bar";
}

// The hit light refreshed over 4 frames (SpecularOptions::refreshInterval) on a camera orbiting
// 1 degree a frame, then resting: every frame after the first says it refreshed a quarter of the
// tiles; the glass sphere's pixels against the reference as with every pixel shaded (within
// 0.1 dB), and against the renderer shading every pixel in every frame. The must-fail: a frame of
// the orbit taken for the next, as a reuse without the hit test would, is far from it by the
// same bar. After an object
// moved, nothing is reused.
TEST_F(GovernedQuality, SpecularRefreshOnAMovingCameraAgainstTheReference) {
    test::CausticScene s = test::makeCausticScene({});
    s.cam = test::smallCamera(256, 192, 300.0);
    const int frames = 8;
    auto poseAt = [](int k) { return orbit(std::min(k, 5) * 1.0); };  // frames 5-7 at rest
    s.pose = poseAt(frames - 1);
    const test::CausticReferenceRender ref = test::renderCausticReference(s, 16, 25);
    const cv::Mat sphere = test::sphereMask(test::sphereView(s), 0.98);
    ASSERT_GT(cv::countNonZero(sphere), 300);
    Renderer every(s.scene, s.cam, options());
    Renderer reusing(s.scene, s.cam, options({{"specular_refresh", "4"}}));
    cv::Mat before, lastMove;  // the frames before and after the last step of the orbit
    double worst = 1e9;
    for (int k = 0; k < frames; ++k) {
        if (k == 5) before = every.compositeSrgb().clone();
        every.render({poseAt(k), ref.footage, k == 0});
        if (k == 5) lastMove = every.compositeSrgb().clone();
        const FrameReport& rep = reusing.render({poseAt(k), ref.footage, k == 0});
        const bool reused =
            passReason(rep, "speclight").find("1/4 of the tiles refreshed") != std::string::npos;
        EXPECT_EQ(reused, k > 0) << "frame " << k << ": " << passReason(rep, "speclight");
        worst = std::min(worst,
                         test::psnr(reusing.compositeSrgb(), every.compositeSrgb(), 255.0, sphere));
    }
    const double full = test::psnr(every.compositeSrgb(), ref.compositeSrgb, 255.0, sphere);
    const double reuse = test::psnr(reusing.compositeSrgb(), ref.compositeSrgb, 255.0, sphere);
    const double stale = test::psnr(before, lastMove, 255.0, sphere);
    std::cout << "[ specular refresh ] glass sphere, " << cv::countNonZero(sphere)
              << " px against the reference: every pixel every frame " << full
              << " dB, a quarter of the tiles per frame " << reuse
              << " dB; against every pixel shaded, worst frame " << worst
              << " dB; a frame of the orbit against the one before (must-fail) " << stale
              << " dB\n";
    EXPECT_GT(reuse, full - 0.1);
    EXPECT_GT(worst, 45.0);
    EXPECT_LT(stale, 45.0) << "must-fail: a stale frame is caught by the same bar";

    Scene moved = s.scene;
    ScenePlacement placement;
    placement.moveU = 0.03;
    ASSERT_GT(applyPlacement(moved, placement, PlacementPlane{}), 0);
    ASSERT_TRUE(reusing.updateTransforms(moved));
    const FrameReport& rep = reusing.render({s.pose, ref.footage, false});
    EXPECT_NE(passReason(rep, "speclight").find("every pixel refreshed"), std::string::npos)
        << passReason(rep, "speclight");
}

// Renderer::setQuality between frames gives the frames of a renderer built with those options
// (the half-resolution programs and targets are made on first use), and back.
TEST_F(GovernedQuality, SetQualityEqualsARendererBuiltWithIt) {
    const test::CausticScene s = test::makeCausticScene({});
    const QualitySetting low = {{"specular_trace_resolution", "half"},
                                {"specular_resolution", "half"},
                                {"caustic_refresh", "2"},
                                {"second_exit", "off"}};
    Renderer switched(s.scene, s.cam, options());
    Renderer built(s.scene, s.cam, options(low));
    Renderer full(s.scene, s.cam, options());
    // As live makes it under a frame-time budget: the half-resolution programs built up front
    // (the frame that switches to them does not compile them); the same images as `switched`.
    RendererOptions preparedOptions = options();
    preparedOptions.specular.prepareGovernedVariants = true;
    Renderer prepared(s.scene, s.cam, preparedOptions);
    for (int k = 0; k < 4; ++k) {
        const Pose pose = orbit(1.0 * k);
        if (k == 1) switched.setQuality(options(low));
        if (k == 3) switched.setQuality(options());
        RendererOptions preparedNow = k == 1 || k == 2 ? options(low) : options();
        preparedNow.specular.prepareGovernedVariants = true;
        if (k == 1 || k == 3) prepared.setQuality(preparedNow);
        switched.render({pose, cv::Mat(), k == 0});
        built.render({pose, cv::Mat(), k == 0});
        full.render({pose, cv::Mat(), k == 0});
        prepared.render({pose, cv::Mat(), k == 0});
        EXPECT_GT(test::psnr(prepared.compositeSrgb(), switched.compositeSrgb(), 255.0), 60.0)
            << "frame " << k;
        const Renderer& same = k == 0 || k == 3 ? full : built;
        const double p = test::psnr(switched.compositeSrgb(), same.compositeSrgb(), 255.0);
        std::cout << "[ setQuality ] frame " << k << ": " << p << " dB against the renderer built "
                  << (k == 0 || k == 3 ? "full" : "low") << "\n";
        // Frame 3 is back at full quality: its caustic history came from the low frames.
        EXPECT_GT(p, k == 3 ? 40.0 : 50.0) << "frame " << k;
    }
    RendererOptions bad = options();
    bad.caustic.refreshInterval = 0;
    EXPECT_THROW(switched.setQuality(bad), Error);
    EXPECT_EQ(switched.options().caustic.refreshInterval, 1);
}

}  // namespace
}  // namespace mirage::render
