// Anti-aliasing of what the renderer adds (render/passes/aa, docs/camera-matching.md
// "Anti-aliasing") against the Embree reference, whose pixels are box-filtered over many samples
// as a camera's optics anti-alias the footage. The scene is the shadow-edge test's: a dark
// virtual box turned 30 degrees about +Y on a real table under a real spot light, so its
// silhouette and its shadow's edges run diagonally across the pixel grid. The edge pixels: those
// within a pixel of the box's silhouette (a pixel centre's ray hits the box or not), and of its
// shadow's edge on the table (the table point's segment to the light crosses the box or not).
// Must-fail: with aa off the silhouette misses the floor. Hard cases: the filter leaves the footage
// bit for bit where the renderer changed nothing; a still camera over many frames stays put; a
// camera jump and a virtual object appearing leave no trace of the frames before.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/gl/Context.h"
#include "core/image/ImageIO.h"
#include "render/Renderer.h"
#include "render/raytrace/DifferentialRendering.h"
#include "render/raytrace/EmbreeDevice.h"
#include "tests/support/TestSupport.h"
#include "testscenes/CausticTestScenes.h"
#include "testscenes/ReferenceFrame.h"
#include "testscenes/RenderTestScenes.h"
#include "testscenes/TurnedBoxScene.h"

namespace mirage::render {
namespace {

// Measured on llvmpipe (reference 64 spp, seed 7; docs/camera-matching.md, "Anti-aliasing"):
// silhouette 17.2 dB off, 25.0 dB on. The shadow's edge: 14.5 dB off, 14.3 dB on: at the default
// 512 shadow texels a texel spans 1.7 pixels there, and the edge's error is where the texel
// steps put it, which no filter of the final image can move (docs/realtime-renderer.md,
// "Shadow edges": PCF at a finer map); the filter must not make it worse by more than kShadowSlack.
constexpr double kSilhouettePsnrFloor = 22.0;
constexpr double kShadowSlackDb = 0.5;

using EdgeScene = test::TurnedBoxScene;
using test::segmentHitsBox;

EdgeScene makeScene() {
    return test::makeTurnedBoxScene();
}

struct EdgeMasks {
    cv::Mat silhouette;  // CV_8U 255: within a pixel of the box's silhouette
    cv::Mat shadowEdge;  // within a pixel of its shadow's edge on the table
};

// Pixels with a pixel of either side of a boundary in their 3x3 neighbourhood.
cv::Mat boundaryBand(const cv::Mat& inside, const cv::Mat& domain) {
    const cv::Mat k = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
    cv::Mat a, b;
    cv::dilate(inside, a, k);
    cv::dilate(domain & ~inside, b, k);
    return a & b;
}

EdgeMasks edgeMasks(const EdgeScene& s) {
    const int w = s.cam.width, h = s.cam.height;
    cv::Mat box(h, w, CV_8U, cv::Scalar(0)), table(h, w, CV_8U, cv::Scalar(0));
    cv::Mat shadow(h, w, CV_8U, cv::Scalar(0));
    const glm::dvec3 eye = s.pose.translation;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const glm::dvec3 d =
                s.pose.rotation * glm::normalize(glm::dvec3((x - s.cam.cx) / s.cam.fx,
                                                            (y - s.cam.cy) / s.cam.fy, 1.0));
            if (segmentHitsBox(s, eye, eye + 5.0 * d)) {
                box.at<uint8_t>(y, x) = 255;
                continue;
            }
            if (d.y >= 0) continue;
            const glm::dvec3 p = eye + d * (-eye.y / d.y);
            table.at<uint8_t>(y, x) = 255;
            if (segmentHitsBox(s, p + glm::dvec3(0, 1e-4, 0), glm::dvec3(s.lightPos)))
                shadow.at<uint8_t>(y, x) = 255;
        }
    const cv::Mat all(h, w, CV_8U, cv::Scalar(255));
    EdgeMasks m;
    m.silhouette = boundaryBand(box, all);
    // The shadow's edge on the table away from the silhouette (where the shadow meets the box's
    // base, the silhouette's band counts it).
    m.shadowEdge = boundaryBand(shadow, table) & table & ~m.silhouette;
    return m;
}

struct Reference {
    cv::Mat footage;    // 8-bit sRGB BGR: the reference's real-only render
    cv::Mat composite;  // 8-bit sRGB BGR: the reference differential composite
};

Reference reference(const EdgeScene& s) {
    const test::ReferenceFrame f = test::renderReferenceFrame(s.scene, s.cam, s.pose, 64, 7);
    return {f.footage, f.composite};
}

RendererOptions options(bool aa) {
    RendererOptions opt;
    opt.temporalBlend = 0.0f;
    opt.aa.enabled = aa;
    return opt;
}

cv::Mat renderOnce(const EdgeScene& s, const cv::Mat& footage, bool aa) {
    Renderer r(s.scene, s.cam, options(aa));
    r.render({s.pose, footage, true});
    EXPECT_TRUE(cv::checkRange(r.compositeLinear())) << "NaN/Inf in the composite";
    return r.compositeSrgb();
}

class Antialias : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        context_ = new gl::Context(gl::Context::headless());
        scene_ = new EdgeScene(makeScene());
        reference_ = new Reference(reference(*scene_));
    }
    static void TearDownTestSuite() {
        delete reference_;
        delete scene_;
        delete context_;
    }
    static gl::Context* context_;
    static EdgeScene* scene_;
    static Reference* reference_;
};
gl::Context* Antialias::context_ = nullptr;
EdgeScene* Antialias::scene_ = nullptr;
Reference* Antialias::reference_ = nullptr;

TEST_F(Antialias, EdgesMatchTheReferenceWithAntialiasingAndFailWithout) {
    const EdgeScene& s = *scene_;
    const Reference& ref = *reference_;
    const EdgeMasks m = edgeMasks(s);
    ASSERT_GT(cv::countNonZero(m.silhouette), 300) << "the box's silhouette is not in view";
    ASSERT_GT(cv::countNonZero(m.shadowEdge), 150) << "its shadow's edge is not in view";
    const cv::Mat off = renderOnce(s, ref.footage, false);
    const cv::Mat on = renderOnce(s, ref.footage, true);
    const auto psnr = [&](const cv::Mat& img, const cv::Mat& mask) {
        return test::psnr(img, ref.composite, 255.0, mask);
    };
    const double silOff = psnr(off, m.silhouette), silOn = psnr(on, m.silhouette);
    const double shOff = psnr(off, m.shadowEdge), shOn = psnr(on, m.shadowEdge);
    std::cout << "[ aa ] silhouette " << cv::countNonZero(m.silhouette) << " px: off " << silOff
              << " dB, on " << silOn << " dB; shadow edge " << cv::countNonZero(m.shadowEdge)
              << " px: off " << shOff << " dB, on " << shOn << " dB; whole frame off "
              << psnr(off, {}) << " on " << psnr(on, {}) << " dB\n";
    const auto dir = std::filesystem::path(MIRAGE_TEST_OUTPUT_DIR) / "aa";
    std::filesystem::create_directories(dir);
    const cv::Rect crop =
        (cv::boundingRect(m.silhouette | m.shadowEdge) + cv::Size(8, 8) - cv::Point(4, 4)) &
        cv::Rect(0, 0, off.cols, off.rows);
    cv::Mat side;
    cv::hconcat(std::vector<cv::Mat>{ref.footage(crop), off(crop), on(crop), ref.composite(crop)},
                side);
    cv::resize(side, side, cv::Size(), 4.0, 4.0, cv::INTER_NEAREST);
    writeBgr8(dir / "edges_footage_off_on_truth.png", side);
    EXPECT_GE(silOn, kSilhouettePsnrFloor);
    EXPECT_LT(silOff, kSilhouettePsnrFloor) << "must-fail: the silhouette without anti-aliasing";
    EXPECT_GE(shOn, shOff - kShadowSlackDb) << "the filter spoils the shadow's edge";
}

// Where neither a pixel nor its 4 neighbours were changed by the renderer, the filtered
// composite is the footage bit for bit (8-bit sRGB, as the camera delivered it).
TEST_F(Antialias, FootageStaysBitIdenticalWhereTheRendererChangedNothing) {
    const EdgeScene& s = *scene_;
    Renderer r(s.scene, s.cam, options(false));
    r.render({s.pose, reference_->footage, true});
    cv::Mat delta, maxDelta;
    cv::absdiff(r.compositeLinear(), srgbBgr8ToLinearRgb(reference_->footage), delta);
    // The largest channel's change per pixel.
    cv::reduce(delta.reshape(1, int(delta.total())), maxDelta, 1, cv::REDUCE_MAX);
    maxDelta = maxDelta.reshape(1, delta.rows);
    const cv::Mat changed = maxDelta > RendererOptions{}.aa.changeEpsilon;
    cv::Mat near;
    cv::dilate(changed, near, cv::getStructuringElement(cv::MORPH_CROSS, cv::Size(3, 3)));
    const cv::Mat untouched = near == 0;
    // The spot light's bounce off the virtual box changes most of the table a little: the
    // untouched pixels are those outside its cone.
    ASSERT_GT(cv::countNonZero(untouched), 500);
    const cv::Mat on = renderOnce(s, reference_->footage, true);
    const auto differing = [](const cv::Mat& a, const cv::Mat& b) {
        cv::Mat d, m;
        cv::absdiff(a, b, d);
        cv::reduce(d.reshape(1, int(d.total())), m, 1, cv::REDUCE_MAX);
        return cv::Mat(m.reshape(1, a.rows) > 0);
    };
    EXPECT_EQ(cv::countNonZero(differing(on, reference_->footage) & untouched), 0)
        << "the filter changed footage pixels the renderer left alone";
    // ... and it did change pixels next to the renderer's edges.
    EXPECT_GT(cv::countNonZero(differing(on, r.compositeSrgb())), 50);
}

// The 99.9th percentile of the per-channel 8-bit difference of two images.
double differencePercentile(const cv::Mat& a, const cv::Mat& b) {
    cv::Mat d;
    cv::absdiff(a, b, d);
    const cv::Mat flat = d.reshape(1, 1).clone();
    std::vector<uint8_t> v(flat.begin<uint8_t>(), flat.end<uint8_t>());
    std::sort(v.begin(), v.end());
    return v[size_t(0.999 * double(v.size() - 1))];
}

// A still camera over many frames (the GI's temporal smoothing on, as in a live session): the
// filtered edges settle and stay, no drift from frame to frame, and the last frame's edges are
// as good as the first's.
TEST_F(Antialias, StillCameraOverManyFramesIsStable) {
    const EdgeScene& s = *scene_;
    RendererOptions opt = options(true);
    opt.temporalBlend = RendererOptions{}.temporalBlend;
    Renderer r(s.scene, s.cam, opt);
    const EdgeMasks m = edgeMasks(s);
    const cv::Mat edges = m.silhouette | m.shadowEdge;
    std::vector<cv::Mat> frames;
    for (int i = 0; i < 16; ++i) {
        r.render({s.pose, reference_->footage, i == 0});
        frames.push_back(r.compositeSrgb());
    }
    const double first = test::psnr(frames.front(), reference_->composite, 255.0, edges);
    const double last = test::psnr(frames.back(), reference_->composite, 255.0, edges);
    std::cout << "[ aa still ] edges frame 1 " << first << " dB, frame 16 " << last
              << " dB; frames 15-16 differ by " << differencePercentile(frames[14], frames[15])
              << " codes (99.9th pct)\n";
    EXPECT_LE(differencePercentile(frames[14], frames[15]), 1.0) << "the edges drift";
    EXPECT_GE(last, first - 0.1);
}

// A camera jump (no reset flag: the tracker simply reports a far pose) and a virtual object
// appearing: the frame after is what a fresh renderer makes of it, no ghost of the frames before.
TEST_F(Antialias, CameraJumpAndAppearingObjectLeaveNoGhost) {
    const EdgeScene& s = *scene_;
    const RendererOptions opt = options(true);
    Renderer fresh(s.scene, s.cam, opt);
    fresh.render({s.pose, reference_->footage, true});
    const cv::Mat expected = fresh.compositeSrgb();

    Renderer jumped(s.scene, s.cam, opt);
    const Pose away = test::lookAtPose({0.45, 0.40, 0.35}, {0.05, 0.0, 0.0});
    for (int i = 0; i < 4; ++i) jumped.render({away, reference_->footage, i == 0});
    jumped.render({s.pose, reference_->footage, false});
    const double jumpPsnr = test::psnr(jumped.compositeSrgb(), expected, 255.0);

    // The box 5 m away (out of view) for a few frames, then placed.
    Scene hidden = s.scene;
    for (Node& n : hidden.nodes)
        if (n.name == "box")
            n.local = n.world =
                glm::translate(glm::dmat4(1.0), glm::dvec3(5.0, 0.0, 5.0)) * s.boxWorld;
    Renderer appearing(hidden, s.cam, opt);
    for (int i = 0; i < 4; ++i) appearing.render({s.pose, reference_->footage, i == 0});
    ASSERT_TRUE(appearing.updateTransforms(s.scene));
    appearing.render({s.pose, reference_->footage, false});
    const double appearPsnr = test::psnr(appearing.compositeSrgb(), expected, 255.0);
    std::cout << "[ aa hard cases ] after a camera jump " << jumpPsnr
              << " dB from a fresh render; after the object appeared " << appearPsnr << " dB\n";
    EXPECT_GE(jumpPsnr, 45.0);
    EXPECT_GE(appearPsnr, 45.0);
}

}  // namespace
}  // namespace mirage::render
