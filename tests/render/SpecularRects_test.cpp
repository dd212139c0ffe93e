// The specular passes draw over each specular object's own canvas rectangle (and the refraction
// search over the glass objects' only) instead of one rectangle around all of them: the images
// must not change, and on the tabletop (a mirror and a glass sphere apart on screen) the
// rectangles must cover clearly fewer pixels than the one around both.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <tuple>
#include <vector>

#include <opencv2/core.hpp>

#include "core/scene/Scene.h"
#include "render/FrameContext.h"
#include "render/Renderer.h"
#include "render/passes/direct/DirectLightPass.h"
#include "render/passes/fuzzy/FuzzyReflectionPass.h"
#include "render/passes/gbuffer/GBufferPass.h"
#include "render/passes/specular/SpecularGBufferPass.h"
#include "render/passes/specular/SpecularLightPass.h"
#include "tests/support/HeadlessGlSuite.h"
#include "tests/support/TestSupport.h"
#include "testscenes/RenderTestScenes.h"

namespace mirage::render {
namespace {

long long area(const std::vector<glm::ivec4>& rects) {
    long long a = 0;
    for (const glm::ivec4& r : rects) a += (long long)r.z * r.w;
    return a;
}

bool overlap(const glm::ivec4& a, const glm::ivec4& b) {
    return a.x < b.x + b.z && b.x < a.x + a.z && a.y < b.y + b.w && b.y < a.y + a.w;
}

bool covers(const std::vector<glm::ivec4>& rects, int x, int y) {
    for (const glm::ivec4& r : rects)
        if (x >= r.x && x < r.x + r.z && y >= r.y && y < r.y + r.w) return true;
    return false;
}

TEST(SpecularRects, OverlappingRectanglesAreMergedAndTheRestKept) {
    // Two apart, one touching the first's right edge (not overlapping), one empty.
    const std::vector<glm::ivec4> apart = {
        {0, 0, 10, 10}, {50, 50, 10, 10}, {10, 0, 5, 5}, {3, 3, 0, 7}};
    const auto kept = mergeOverlappingRects(apart);
    ASSERT_EQ(kept.size(), 3u);
    EXPECT_EQ(area(kept), 100 + 100 + 25);
    // A chain: a overlaps b, and only their union overlaps c.
    const std::vector<glm::ivec4> chain = {{0, 0, 10, 10}, {8, 0, 10, 4}, {16, 6, 6, 6}};
    const auto merged = mergeOverlappingRects(chain);
    ASSERT_EQ(merged.size(), 1u);
    EXPECT_EQ(merged[0], glm::ivec4(0, 0, 22, 12));
    // Whatever the input, the output covers every input pixel and no two outputs overlap.
    std::vector<glm::ivec4> many;
    for (int i = 0; i < 12; ++i) many.push_back({(i * 37) % 90, (i * 53) % 70, 8 + i, 12 - i / 2});
    const auto out = mergeOverlappingRects(many);
    for (size_t i = 0; i < out.size(); ++i)
        for (size_t j = i + 1; j < out.size(); ++j) EXPECT_FALSE(overlap(out[i], out[j]));
    for (const glm::ivec4& r : many)
        for (int y = r.y; y < r.y + r.w; ++y)
            for (int x = r.x; x < r.x + r.z; ++x) ASSERT_TRUE(covers(out, x, y)) << x << "," << y;
}

// The glass rectangles and the mirror ones drawn with their own variants never share a pixel.
TEST(SpecularRects, MirrorRectanglesThatMeetAGlassOneJoinIt) {
    std::vector<glm::ivec4> glass = {{0, 0, 10, 10}, {30, 0, 10, 10}};
    // One apart, one touching the first glass rectangle (after half-pixel rounding, say), one
    // that meets only the union the first move makes.
    std::vector<glm::ivec4> mirror = {{60, 60, 5, 5}, {9, 2, 6, 4}, {14, 8, 5, 5}};
    separateMirrorRects(glass, mirror);
    ASSERT_EQ(mirror.size(), 1u);
    EXPECT_EQ(mirror[0], glm::ivec4(60, 60, 5, 5));
    for (const glm::ivec4& m : mirror)
        for (const glm::ivec4& g : glass) EXPECT_FALSE(overlap(m, g));
    for (int y = 2; y < 6; ++y)
        for (int x = 9; x < 15; ++x) EXPECT_TRUE(covers(glass, x, y));
    for (int y = 8; y < 13; ++y)
        for (int x = 14; x < 19; ++x) EXPECT_TRUE(covers(glass, x, y));
}

class SpecularRectsRender : public test::HeadlessGlSuite {};

struct Frame {
    cv::Mat composite, reflection, refraction, specularRv, directRv, lightRv;
    std::vector<glm::ivec4> rects, glassRects;
};

const CameraIntrinsics kCamera = test::smallCamera(160, 120, 130.0);
// The tabletop's mirror on the left, the glass sphere in front of the board: apart on screen.
const Pose kPose = test::lookAtPose({0.05, 0.40, 0.60}, {-0.05, 0.02, 0.0});
// Another view: both objects elsewhere on screen.
const Pose kOtherPose = test::lookAtPose({-0.25, 0.35, 0.55}, {0.05, 0.0, -0.05});

RendererOptions options(bool perObject, bool half = false) {
    RendererOptions o;
    o.specular.halfResolution = half;
    o.specular.halfResolutionTrace = half;
    o.vpl.count = 64;
    o.temporalBlend = 0.0f;
    o.specular.rectsPerObject = perObject;
    o.direct.keepDirectLight = true;  // DirectRv apart from LRv (the tabletop has VPL light)
    return o;
}

void renderFrame(Renderer& r, const Pose& pose) {
    const cv::Mat footage(kCamera.height, kCamera.width, CV_8UC3, cv::Scalar(90, 110, 130));
    r.render({pose, footage, true});
}

Frame readFrame(const Renderer& r) {
    Frame f;
    f.composite = r.compositeLinear();
    f.reflection = r.readBuffer(kReflectionGBuffer);
    f.refraction = r.readBuffer(kRefractionGBuffer);
    f.specularRv = r.readBuffer(kSpecularRv);
    f.directRv = r.readBuffer(kDirectRv);
    f.lightRv = r.readBuffer(kLRv);
    f.rects = r.specularRects();
    f.glassRects = r.refractiveRects();
    return f;
}

Frame render(const Scene& scene, bool perObject, bool half = false) {
    Renderer r(scene, kCamera, options(perObject, half));
    renderFrame(r, kPose);
    return readFrame(r);
}

double maxAbsDiff(const cv::Mat& a, const cv::Mat& b) {
    return cv::norm(a, b, cv::NORM_INF);
}

TEST_F(SpecularRectsRender, PerObjectRectanglesChangeNoPixelAndCoverFewer) {
    const Scene scene = loadScene(test::dataDir() / "scenes" / "tabletop" / "tabletop.gltf");
    const Frame perObject = render(scene, true);
    const Frame one = render(scene, false);
    ASSERT_EQ(one.rects.size(), 1u);
    for (const glm::ivec4& r : perObject.rects)
        std::cout << "specular rect " << r.x << "," << r.y << " " << r.z << "x" << r.w << "\n";
    for (const glm::ivec4& r : perObject.glassRects)
        std::cout << "glass rect " << r.x << "," << r.y << " " << r.z << "x" << r.w << "\n";
    std::cout << "pixels: per object " << area(perObject.rects) << " (glass "
              << area(perObject.glassRects) << "), one rectangle " << area(one.rects) << "\n";
    // The scene must exercise the split: two objects apart, the glass one alone refracting.
    EXPECT_EQ(perObject.rects.size(), 2u);
    EXPECT_EQ(perObject.glassRects.size(), 1u);
    EXPECT_LT(area(perObject.rects), area(one.rects) * 3 / 4);
    EXPECT_LT(area(perObject.glassRects), area(perObject.rects) * 3 / 4);

    EXPECT_LT(maxAbsDiff(perObject.composite, one.composite), 1e-5);
    EXPECT_LT(maxAbsDiff(perObject.reflection, one.reflection), 1e-5);
    EXPECT_LT(maxAbsDiff(perObject.refraction, one.refraction), 1e-5);
    EXPECT_LT(maxAbsDiff(perObject.specularRv, one.specularRv), 1e-5);

    // The comparison sees a change confined to the glass pixels: a glass sphere of index 1.45
    // instead of 1.5 changes the refraction buffer and the composite.
    Scene lowerIor = scene;
    bool changed = false;
    for (Material& m : lowerIor.materials)
        if (m.isTransmissive() && !m.isMirror()) m.ior -= 0.05f, changed = true;
    ASSERT_TRUE(changed);
    const Frame other = render(lowerIor, true);
    EXPECT_GT(maxAbsDiff(other.refraction, one.refraction), 1e-3);
    EXPECT_GT(maxAbsDiff(other.composite, one.composite), 1e-3);
}

// The same at half resolution (the trace and the lighting: their mirror rectangles take the
// reflection-only variants too).
TEST_F(SpecularRectsRender, PerObjectRectanglesChangeNoPixelAtHalfResolution) {
    const Scene scene = loadScene(test::dataDir() / "scenes" / "tabletop" / "tabletop.gltf");
    const Frame perObject = render(scene, true, true);
    const Frame one = render(scene, false, true);
    ASSERT_EQ(perObject.rects.size(), 2u);
    EXPECT_LT(maxAbsDiff(perObject.composite, one.composite), 1e-5);
    EXPECT_LT(maxAbsDiff(perObject.reflection, one.reflection), 1e-5);
    EXPECT_LT(maxAbsDiff(perObject.specularRv, one.specularRv), 1e-5);
    // The refraction buffer only where there is glass (the mirror's rectangle no longer traces
    // it at half resolution).
    const Frame full = render(scene, false, false);
    EXPECT_GT(maxAbsDiff(perObject.composite, full.composite), 1e-3)
        << "half resolution changes the image, so the comparison can fail";
}

// The passes clear only the pixels the last frame's rectangles and this frame's cover: a frame
// after one seen from elsewhere must hold exactly what a first frame from its own view holds,
// zeros outside its rectangles included.
TEST_F(SpecularRectsRender, NoPixelOfTheFrameBeforeIsLeftOutsideTheRectangles) {
    const Scene scene = loadScene(test::dataDir() / "scenes" / "tabletop" / "tabletop.gltf");
    Renderer moved(scene, kCamera, options(true));
    renderFrame(moved, kOtherPose);
    const Frame before = readFrame(moved);
    renderFrame(moved, kPose);
    const Frame after = readFrame(moved);
    const Frame fresh = render(scene, true);
    // The earlier frame's objects lie where this frame's rectangles do not reach.
    long long outside = 0;
    for (const glm::ivec4& r : before.rects)
        for (int y = r.y; y < r.y + r.w; ++y)
            for (int x = r.x; x < r.x + r.z; ++x) outside += covers(after.rects, x, y) ? 0 : 1;
    std::cout << outside << " pixels of the earlier frame's rectangles lie outside this one's\n";
    ASSERT_GT(outside, 1000);
    // And its buffers differ from this frame's there: a pass that cleared only the new
    // rectangles would leave them.
    ASSERT_GT(maxAbsDiff(before.reflection, fresh.reflection), 1e-2);
    EXPECT_LT(maxAbsDiff(after.composite, fresh.composite), 1e-5);
    EXPECT_LT(maxAbsDiff(after.reflection, fresh.reflection), 1e-5);
    EXPECT_LT(maxAbsDiff(after.refraction, fresh.refraction), 1e-5);
    EXPECT_LT(maxAbsDiff(after.specularRv, fresh.specularRv), 1e-5);
    // The diffuse passes skip the specular pixels and clear them inside this frame's rectangles.
    EXPECT_LT(maxAbsDiff(after.directRv, fresh.directRv), 1e-5);
    EXPECT_LT(maxAbsDiff(after.lightRv, fresh.lightRv), 1e-5);
}

// The diffuse lighting passes (direct light, the GI upsample, the composite's diffuse variant)
// skip the pixels that show a mirror or glass object, whose light the composite takes from the
// specular passes: the composite must not change, and those pixels must hold 0 in the diffuse
// buffers (shaded, they hold light: the comparison can see the skip).
TEST_F(SpecularRectsRender, DiffusePassesSkipTheSpecularPixelsAndChangeNoCompositePixel) {
    const Scene scene = loadScene(test::dataDir() / "scenes" / "tabletop" / "tabletop.gltf");
    auto renderWith = [&](bool diffuseOnSpecular, const CameraIntrinsics& camera) {
        RendererOptions o = options(true);
        o.direct.onSpecularPixels = diffuseOnSpecular;
        Renderer r(scene, camera, o);
        const cv::Mat footage(camera.height, camera.width, CV_8UC3, cv::Scalar(90, 110, 130));
        r.render({kPose, footage, true});
        return std::make_tuple(r.compositeLinear(), r.readBuffer(kDirectRv), r.readBuffer(kLRv),
                               r.readBuffer(kSpecularMask));
    };
    const auto [skipped, skippedDirect, skippedLight, mask] = renderWith(false, kCamera);
    const auto [shaded, shadedDirect, shadedLight, mask2] = renderWith(true, kCamera);
    int specularPixels = 0, litWhenShaded = 0;
    double heldWhenSkipped = 0.0;
    for (int y = 0; y < mask.rows; ++y)
        for (int x = 0; x < mask.cols; ++x) {
            if (mask.at<float>(y, x) > 0.5f) continue;
            ++specularPixels;
            const cv::Vec3f d = shadedDirect.at<cv::Vec3f>(y, x);
            litWhenShaded += d[0] + d[1] + d[2] > 1e-3f ? 1 : 0;
            for (const cv::Mat* m : {&skippedDirect, &skippedLight}) {
                const cv::Vec3f v = m->at<cv::Vec3f>(y, x);
                heldWhenSkipped = std::max(
                    heldWhenSkipped, double(std::abs(v[0]) + std::abs(v[1]) + std::abs(v[2])));
            }
        }
    std::cout << specularPixels << " specular pixels, " << litWhenShaded
              << " of them lit when the diffuse passes shade them\n";
    ASSERT_GT(specularPixels, 1000);
    ASSERT_GT(litWhenShaded, specularPixels / 10);
    EXPECT_EQ(heldWhenSkipped, 0.0);
    EXPECT_LT(maxAbsDiff(skipped, shaded), 1e-5);

    // Under lens distortion the composite reads the canvas bilinearly: a camera pixel beside a
    // specular silhouette may blend in a skipped (black) neighbour's light. Its real-object
    // pixels keep their ratio (L_rv and L_r scale alike); the change stays small and rare.
    CameraIntrinsics distorted = kCamera;
    distorted.distortion = {-0.25, 0.08, 0.0, 0.0, 0.0};
    const cv::Mat a = std::get<0>(renderWith(false, distorted));
    const cv::Mat b = std::get<0>(renderWith(true, distorted));
    cv::Mat diff;
    cv::absdiff(a, b, diff);
    std::vector<cv::Mat> channels;
    cv::split(diff, channels);
    const cv::Mat rgbMax = cv::max(cv::max(channels[0], channels[1]), channels[2]);
    const int changed = cv::countNonZero(rgbMax > 1e-3);
    std::cout << changed << " of " << a.total() << " pixels changed under distortion, mean "
              << cv::mean(rgbMax)[0] << "\n";
    EXPECT_LT(changed, int(a.total() / 50));
    EXPECT_LT(cv::mean(rgbMax)[0], 2e-3);
    EXPECT_TRUE(cv::checkRange(a));
}

// The same for the rough passes (the fuzzy filter and the rough-glass prefilter clear only what
// their last draw and this one cover): frosted glass and brushed metal, two views.
TEST_F(SpecularRectsRender, RoughPassesLeaveNoPixelOfTheFrameBefore) {
    const Scene scene = loadScene(test::dataDir() / "scenes" / "tabletop" / "tabletop_rough.gltf");
    const Pose other = test::lookAtPose({0.45, 0.30, 0.10}, {-0.10, 0.02, -0.05});
    Renderer moved(scene, kCamera, options(true));
    renderFrame(moved, other);
    const cv::Mat before = moved.readBuffer(kSpecularRv);
    const cv::Mat beforeRough = moved.readBuffer(kFilteredVideo);
    renderFrame(moved, kPose);
    Renderer fresh(scene, kCamera, options(true));
    renderFrame(fresh, kPose);
    ASSERT_GT(maxAbsDiff(before, fresh.readBuffer(kSpecularRv)), 1e-2);
    ASSERT_GT(maxAbsDiff(beforeRough, fresh.readBuffer(kFilteredVideo)), 1e-2);
    for (Resource r : {kSpecularRv, kSpecularR, kLenv, kFilteredVideo})
        EXPECT_LT(maxAbsDiff(moved.readBuffer(r), fresh.readBuffer(r)), 1e-5) << resourceName(r);
    EXPECT_LT(maxAbsDiff(moved.compositeLinear(), fresh.compositeLinear()), 1e-5);
}

// The edges of the rectangles: a camera inside an object's bounding sphere (here inside the
// glass sphere itself) sees it over the whole canvas, and objects out of view give none and no
// specular pass.
TEST_F(SpecularRectsRender, CameraInsideABoundingSphereTakesTheWholeCanvasAndNoneInViewTakesNone) {
    const Scene scene = loadScene(test::dataDir() / "scenes" / "tabletop" / "tabletop.gltf");
    Renderer inside(scene, kCamera, options(true));
    // The glass sphere's centre (tabletop.gltf), looking along +x over the table.
    renderFrame(inside, test::lookAtPose({0.02, 0.045, 0.16}, {0.5, 0.045, 0.16}));
    const glm::ivec4 whole(0, 0, kCamera.width, kCamera.height);
    ASSERT_EQ(inside.specularRects().size(), 1u);
    EXPECT_EQ(inside.specularRects()[0], whole);
    ASSERT_EQ(inside.refractiveRects().size(), 1u);
    EXPECT_EQ(inside.refractiveRects()[0], whole);
    EXPECT_TRUE(cv::checkRange(inside.compositeLinear()));

    Renderer away(scene, kCamera, options(true));
    // From above the table's far edge, looking away from the objects and up.
    const cv::Mat footage(kCamera.height, kCamera.width, CV_8UC3, cv::Scalar(90, 110, 130));
    const FrameReport& report =
        away.render({test::lookAtPose({0.0, 0.3, -0.6}, {0.0, 0.8, -2.0}), footage, true});
    EXPECT_TRUE(away.specularRects().empty());
    EXPECT_TRUE(away.refractiveRects().empty());
    EXPECT_FALSE(report.ran("specgbuf"));
    EXPECT_TRUE(cv::checkRange(away.compositeLinear()));
}

}  // namespace
}  // namespace mirage::render
