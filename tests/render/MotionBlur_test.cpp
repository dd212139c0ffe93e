// Motion blur of what the renderer adds (render/passes/motionblur, docs/camera-matching.md): the
// whole renderer against the reference renderer's ground truth of a synthetic fast pan filmed
// with the shutter open half the frame interval (blurred footage and truth), blurred and not;
// and the hard cases: a still camera (the composite unchanged), a huge motion (clamped, finite),
// the first frame (no previous pose), a frame after a lost frame, a long gap, no frame time.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <limits>

#include <opencv2/core.hpp>

#include "core/Error.h"
#include "core/camera/CalibrationFile.h"
#include "core/gl/Context.h"
#include "core/image/ImageIO.h"
#include "core/session/Session.h"
#include "render/Renderer.h"
#include "render/evaluation/RealtimeBench.h"
#include "render/passes/motionblur/MotionBlurPass.h"
#include "render/raytrace/GroundTruthComposite.h"
#include "render/raytrace/SyntheticSession.h"
#include "tests/support/TestSupport.h"
#include "testscenes/RenderTestScenes.h"
#include "testscenes/SmallSyntheticSession.h"

namespace mirage::render {
namespace {

namespace fs = std::filesystem;

Scene tableScene() {
    return test::spotLitTableWithVirtualBox();
}
const Pose kOverview = test::spotLitTableOverview();

RendererOptions blurring(double shutter) {
    RendererOptions o;
    o.motionBlur.shutterSeconds = shutter;
    return o;
}

double maxAbsDifference(const cv::Mat& a, const cv::Mat& b) {
    double m = 0;
    cv::minMaxLoc(cv::abs(a - b), nullptr, &m);
    return m;
}

// ---- hard cases ---------------------------------------------------------------------------------

TEST(MotionBlur, FirstFrameAndAStillCameraLeaveTheCompositeUnchanged) {
    gl::Context context = gl::Context::headless();
    const Scene scene = tableScene();
    const CameraIntrinsics camera = test::smallCamera();
    Renderer sharp(scene, camera), blurred(scene, camera, blurring(0.05));
    const cv::Mat footage(camera.height, camera.width, CV_8UC3, cv::Scalar(90, 110, 120));
    for (int f = 0; f < 3; ++f) {
        sharp.render({kOverview, footage, f == 0, f / 10.0});
        blurred.render({kOverview, footage, f == 0, f / 10.0});
        if (f == 0) {
            EXPECT_FALSE(blurred.lastReport().ran("motionblur"));
            EXPECT_NE(blurred.lastReport().summary().find("first frame"), std::string::npos)
                << blurred.lastReport().summary();
        } else {
            EXPECT_TRUE(blurred.lastReport().ran("motionblur")) << blurred.lastReport().summary();
        }
        // No motion: nothing to blur, whatever the shutter.
        EXPECT_LT(maxAbsDifference(blurred.compositeLinear(), sharp.compositeLinear()), 1e-6) << f;
    }
    EXPECT_FALSE(sharp.lastReport().ran("motionblur"));
}

TEST(MotionBlur, AHugeMotionIsClampedAndStaysFinite) {
    gl::Context context = gl::Context::headless();
    const Scene scene = tableScene();
    const CameraIntrinsics camera = test::smallCamera();
    RendererOptions o = blurring(1.0);
    Renderer r(scene, camera, o);
    const cv::Mat footage(camera.height, camera.width, CV_8UC3, cv::Scalar(90, 110, 120));
    r.render({kOverview, footage, true, 0.0});
    // A quarter turn and a jump in a millisecond with a 1 s shutter: thousands of pixels.
    const Pose away = test::lookAtPose({2.5, 0.3, 0.1}, {0, 0.2, 0});
    r.render({away, footage, false, 0.001});
    ASSERT_TRUE(r.lastReport().ran("motionblur")) << r.lastReport().summary();
    const cv::Mat velocity = r.readBuffer(kMotionVelocity);
    ASSERT_TRUE(cv::checkRange(velocity));
    double maxLength = 0;
    for (int y = 0; y < velocity.rows; ++y)
        for (int x = 0; x < velocity.cols; ++x) {
            const cv::Vec3f v = velocity.at<cv::Vec3f>(y, x);
            maxLength = std::max(maxLength, std::hypot(double(v[0]), double(v[1])));
        }
    EXPECT_LE(maxLength, o.motionBlur.tileSize * 1.001);
    EXPECT_GT(maxLength, o.motionBlur.tileSize * 0.9);  // it was clamped, not lost
    EXPECT_TRUE(cv::checkRange(r.compositeLinear())) << "NaN or inf in the blurred composite";
    // And back in the opposite direction with a time that does not advance: not blurred.
    r.render({kOverview, footage, false, 0.001});
    EXPECT_FALSE(r.lastReport().ran("motionblur"));
    EXPECT_NE(r.lastReport().summary().find("does not advance"), std::string::npos);
}

TEST(MotionBlur, NoTimeOrALongGapIsNotBlurred) {
    gl::Context context = gl::Context::headless();
    const Scene scene = tableScene();
    const CameraIntrinsics camera = test::smallCamera();
    Renderer r(scene, camera, blurring(0.05));
    const Pose moved = test::lookAtPose({0.3, 2.5, 2.5}, {0, 0, 0});
    r.render({kOverview, cv::Mat(), true, 0.0});
    r.render({moved, cv::Mat(), false});  // no time
    EXPECT_FALSE(r.lastReport().ran("motionblur"));
    EXPECT_NE(r.lastReport().summary().find("unknown"), std::string::npos);
    r.render({kOverview, cv::Mat(), false, 5.0});  // 5 s after a frame of unknown time
    EXPECT_FALSE(r.lastReport().ran("motionblur"));
    r.render({moved, cv::Mat(), false, 6.0});  // a seek: 1 s later
    EXPECT_FALSE(r.lastReport().ran("motionblur"));
    EXPECT_NE(r.lastReport().summary().find("since the previous frame"), std::string::npos);
    r.render({kOverview, cv::Mat(), false, 6.1});
    EXPECT_TRUE(r.lastReport().ran("motionblur")) << r.lastReport().summary();
}

TEST(MotionBlur, BadOptionsAreRefused) {
    RendererOptions o;
    o.motionBlur.shutterSeconds = -0.1;
    EXPECT_THROW(o.validate(), Error);
    o.motionBlur.shutterSeconds = 0.01;
    o.motionBlur.tileSize = 1;
    EXPECT_THROW(o.validate(), Error);
    o.motionBlur.tileSize = 20;
    o.motionBlur.samples = 2;
    EXPECT_THROW(o.validate(), Error);
    o.motionBlur.samples = 15;
    EXPECT_NO_THROW(o.validate());
}

// ---- against ground truth: a fast pan, shutter open half the frame ------------------------------

struct PanSession {
    Session session;
    CameraIntrinsics camera;
    std::vector<BenchFrame> frames;
};

PanSession makeFastPan(const std::string& name, double noise) {
    const fs::path dir = mirage::test::outputDirForThisTest(name);
    raytrace::SyntheticSessionOptions o =
        test::smallSyntheticSession("in-memory motion blur scene", 16, 5);
    o.sensor.noise = noise;
    o.shutter = 0.5;
    o.blurSubframes = 6;
    o.path.orbitFraction = 0.0;  // the whole clip is the pan (mirage synth --pan-fraction 1)
    o.path.shakeFraction = 0.0;
    o.path.panDeg = 24.0;
    o.path.shakeTranslation = 0.0;
    o.path.shakeRotationDeg = 0.0;
    raytrace::writeSyntheticSession(tableScene(), dir, o);
    PanSession p;
    p.session = readSession(dir);
    p.camera = loadSessionCalibration(p.session, "main").intrinsics;
    const auto info = readGroundTruthInfo(dir);
    EXPECT_TRUE(info.has_value());
    p.frames = loadBenchFrames(p.session, *info, p.camera);
    return p;
}

const PanSession& fastPan() {
    static const PanSession s = makeFastPan("fast_pan_shutter", 0.0);
    return s;
}

TEST(MotionBlurGroundTruth, TheSessionStatesItsShutter) {
    const PanSession& p = fastPan();
    ASSERT_TRUE(p.session.cameras.front().shutter.has_value());
    EXPECT_NEAR(*p.session.cameras.front().shutter, 0.5 / 6.0, 1e-12);
    ASSERT_EQ(p.frames.size(), 6u);
    EXPECT_NEAR(p.frames[3].time, 0.5, 1e-12);
}

// Error over the influenced pixels of frames `use` (indices into the session's frames), rendered
// in that order at the ground-truth poses; the first one resets the history.
// realOnly: judged over the real surfaces the virtual objects change (their own pixels left
// out); grain: with the footage's noise matched.
CompositeError judge(const PanSession& p, const std::vector<size_t>& use, bool blur,
                     CompositeError* lastFrame = nullptr, bool realOnly = false,
                     bool grain = false) {
    RendererOptions o;
    o.vpl.count = 256;
    o.grain.noise.enabled = grain;
    if (blur) o.motionBlur.shutterSeconds = *p.session.cameras.front().shutter;
    Renderer r(tableScene(), p.camera, o);
    CompositeErrorAccumulator acc;
    for (size_t k = 0; k < use.size(); ++k) {
        const BenchFrame& f = p.frames[use[k]];
        r.render({f.T_world_camera, f.footage, k == 0 || use[k] != use[k - 1] + 1, f.time});
        if (k == 0) continue;  // the first frame has no motion to blur: judged nowhere
        EXPECT_EQ(r.lastReport().ran("motionblur"), blur) << r.lastReport().summary();
        CompositeErrorAccumulator one;
        cv::Mat influence = f.influence.clone();
        if (realOnly) influence.setTo(0, f.influence == kInfluenceVirtual);
        one.add(r.compositeSrgb(), f.truth, influence);
        acc.merge(one);
        if (lastFrame && k + 1 == use.size()) *lastFrame = one.result();
    }
    return acc.result();
}

TEST(MotionBlurGroundTruth, FastPanWithShutterHalfOpen) {
    gl::Context context = gl::Context::headless();
    const PanSession& p = fastPan();
    const std::vector<size_t> all{0, 1, 2, 3, 4, 5};
    const CompositeError off = judge(p, all, false), on = judge(p, all, true);
    std::cout << "[ fast pan, shutter 0.5 ] influenced PSNR off " << off.psnrInfluenced
              << " dB, SSIM " << off.ssimInfluenced << "; on " << on.psnrInfluenced << " dB, SSIM "
              << on.ssimInfluenced << "\n";
    // Measured (llvmpipe, 160x120, reference 16 spp, 6 sub-frames, frames 1-5): influenced PSNR
    // 23.6 dB / SSIM 0.773 off, 26.2 dB / 0.844 on.
    EXPECT_GE(on.psnrInfluenced, 25.0);
    EXPECT_LT(off.psnrInfluenced, 25.0);  // the floor needs the motion blur
    EXPECT_GT(on.ssimInfluenced, off.ssimInfluenced + 0.03);
}

// Noisy footage: a real surface the renderer darkens (a shadow) has less shot noise than the
// footage. The blur takes the change as a ratio of the footage, so the pixel's own noise is
// scaled with its light; taken as a difference, a shadowed pixel would keep the footage's full
// noise and gain its neighbours' (measured, llvmpipe, 160x120: real changed pixels' PSNR 31.1 dB
// blurred as a ratio, 28.9 as a difference, 27.6 without the blur).
TEST(MotionBlurGroundTruth, NoisyFootageKeepsTheNoiseOfARealPixelAsItsLightScales) {
    gl::Context context = gl::Context::headless();
    const PanSession p = makeFastPan("fast_pan_shutter_noise", 0.01);
    const std::vector<size_t> all{0, 1, 2, 3, 4, 5};
    const CompositeError off = judge(p, all, false, nullptr, true, true),
                         on = judge(p, all, true, nullptr, true, true);
    std::cout << "[ noisy fast pan, shutter 0.5 ] real changed pixels: PSNR off "
              << off.psnrInfluenced << " dB, on " << on.psnrInfluenced << " dB\n";
    EXPECT_GT(on.psnrInfluenced, off.psnrInfluenced + 2.5);
}

TEST(MotionBlurGroundTruth, AFrameAfterALostFrameUsesTheLastRenderedPose) {
    gl::Context context = gl::Context::headless();
    const PanSession& p = fastPan();
    // Frame 3 is lost: frame 4's motion is taken from frame 2, two frame intervals back.
    CompositeError lostOff, lostOn;
    judge(p, {1, 2, 4}, false, &lostOff);
    judge(p, {1, 2, 4}, true, &lostOn);
    std::cout << "[ after a lost frame ] frame 4 influenced PSNR off " << lostOff.psnrInfluenced
              << " dB, on " << lostOn.psnrInfluenced << " dB\n";
    // Measured: 22.3 dB off, 26.5 dB on.
    EXPECT_GT(lostOn.psnrInfluenced, lostOff.psnrInfluenced + 2.0);
}

}  // namespace
}  // namespace mirage::render
