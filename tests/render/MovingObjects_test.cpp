// Objects moved in place (Renderer::updateTransforms): a placement being dragged in `mirage live`
// or an animation. The frame after the move must look like the first frame of a renderer built
// for the moved scene: shadows, indirect light, caustics and the specular objects' impostors all
// follow in that same frame, and the camera-independent passes are reused again once nothing
// moves.
#include <gtest/gtest.h>

#include <iostream>
#include <limits>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "core/Error.h"
#include "core/scene/ScenePlacement.h"
#include "render/GpuScene.h"
#include "render/Renderer.h"
#include "tests/support/HeadlessGlSuite.h"
#include "tests/support/TestSupport.h"
#include "testscenes/RenderTestScenes.h"
#include "testscenes/TranslucentTestScenes.h"

namespace mirage::render {
namespace {

class MovingObjects : public test::HeadlessGlSuite {};

// The tabletop (glass sphere, mirror, yellow box on a real table under a real spot light) seen by
// its main camera, small.
struct Tabletop {
    Scene scene = loadScene(test::dataDir() / "scenes" / "tabletop" / "tabletop.gltf");
    CameraIntrinsics cam = test::smallCamera(128, 96, 100.0);
    Pose pose = test::lookAtPose({0.0, 0.42, 0.55}, {0.0, 0.02, 0.0});
};

// The virtual objects moved 8 cm along the table's x, 4 cm towards the back, turned 25 degrees.
Scene moved(const Scene& s) {
    Scene m = s;
    ScenePlacement p;
    p.moveU = 0.08;
    p.moveV = 0.04;
    p.turnDeg = 25.0;
    EXPECT_GT(applyPlacement(m, p, PlacementPlane{}), 0);
    return m;
}

RendererOptions options() {
    RendererOptions o;
    o.vpl.count = 64;
    return o;
}

const PassReport& passReport(const FrameReport& r, const std::string& name) {
    for (const PassReport& p : r.passes)
        if (p.name == name) return p;
    throw Error("no pass " + name);
}

// Pixels whose composite differs by more than 2/255 in some channel (8-bit sRGB).
cv::Mat changed(const cv::Mat& a, const cv::Mat& b) {
    cv::Mat d;
    cv::absdiff(a, b, d);
    cv::Mat m;
    cv::inRange(d, cv::Scalar(0, 0, 0), cv::Scalar(2, 2, 2), m);
    return m == 0;
}

TEST_F(MovingObjects, FrameAfterAMoveEqualsARendererBuiltForTheMovedScene) {
    const Tabletop t;
    const Scene movedScene = moved(t.scene);
    const cv::Mat footage(t.cam.height, t.cam.width, CV_8UC3, cv::Scalar(90, 110, 130));

    Renderer live(t.scene, t.cam, options());
    live.render({t.pose, footage, true});
    live.render({t.pose, footage, false});
    const cv::Mat before = live.compositeSrgb();
    // Static: the camera-independent passes are reused while nothing moves.
    EXPECT_TRUE(live.lastReport().reused("shadow"));

    ASSERT_TRUE(live.updateTransforms(movedScene));
    const FrameReport& rep = live.render({t.pose, footage, false});
    const cv::Mat after = live.compositeSrgb();
    EXPECT_TRUE(rep.ran("shadow")) << passReport(rep, "shadow").reason;
    EXPECT_TRUE(rep.ran("vpl")) << passReport(rep, "vpl").reason;
    EXPECT_TRUE(rep.ran("ism")) << passReport(rep, "ism").reason;
    EXPECT_TRUE(rep.ran("impostor"));
    EXPECT_NE(passReport(rep, "impostor").reason.find("objects moved"), std::string::npos)
        << passReport(rep, "impostor").reason;
    EXPECT_TRUE(rep.ran("photongbuf"));  // the spot light's caustic follows the glass sphere

    Renderer fresh(movedScene, t.cam, options());
    fresh.render({t.pose, footage, true});
    const cv::Mat expected = fresh.compositeSrgb();

    // The move changes a good part of the image (the objects, their shadows, reflections and
    // caustic): the comparison below can fail, as the frame before the move shows.
    const cv::Mat moves = changed(before, expected);
    ASSERT_GT(cv::countNonZero(moves), 600);
    const double psnrBefore = test::psnr(before, expected, 255.0, moves);
    const double psnrAfter = test::psnr(after, expected, 255.0, moves);
    std::cout << "over the " << cv::countNonZero(moves) << " pixels the move changes: before "
              << psnrBefore << " dB, after " << psnrAfter << " dB\n";
    EXPECT_LT(psnrBefore, 25.0);
    // Same passes on the same scene; what may differ is the ISM pool's float rounding (measured:
    // identical images).
    EXPECT_GT(psnrAfter, 40.0);

    // Nothing moves any more: the static passes are reused again from the next frame on.
    ASSERT_TRUE(live.updateTransforms(movedScene));
    EXPECT_TRUE(live.render({t.pose, footage, false}).reused("shadow"));
    EXPECT_TRUE(passReport(live.lastReport(), "impostor").reason.find("cached") !=
                std::string::npos);
}

TEST_F(MovingObjects, AnotherSceneIsRefusedAndNothingChanges) {
    const Tabletop t;
    Renderer r(t.scene, t.cam, options());
    const cv::Mat footage(t.cam.height, t.cam.width, CV_8UC3, cv::Scalar(90, 110, 130));
    r.render({t.pose, footage, true});
    const cv::Mat first = r.compositeSrgb();

    Scene fewer = moved(t.scene);
    std::erase_if(fewer.roots, [&](int n) { return fewer.nodes[size_t(n)].name == "yellow_box"; });
    ASSERT_EQ(fewer.meshInstances().size() + 1, t.scene.meshInstances().size());
    EXPECT_THROW(r.updateTransforms(fewer), Error);
    Scene broken = moved(t.scene);  // a NaN transform (a broken animation) is refused
    for (Node& n : broken.nodes)
        if (n.name == "yellow_box") n.world[3][0] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(r.updateTransforms(broken), Error);
    Scene noLights = moved(t.scene);
    noLights.lights.clear();
    EXPECT_THROW(r.updateTransforms(noLights), Error);

    // Nothing moved: the same frame again.
    r.render({t.pose, footage, true});
    EXPECT_GT(test::psnr(r.compositeSrgb(), first, 255.0), 40.0);
    EXPECT_EQ(r.gpuScene().generation(), 0u);
}

TEST_F(MovingObjects, GpuSceneMovesBoundsPointsAndLightsOnlyOfWhatMoved) {
    const Tabletop t;
    GpuScene g(t.scene, 16384);  // the renderer's pool
    const std::vector<DrawItem> drawsBefore = g.draws();
    const GpuScene::TransformUpdate same = g.updateTransforms(t.scene);
    EXPECT_FALSE(same.any());
    EXPECT_EQ(g.generation(), 0u);

    const GpuScene::TransformUpdate u = g.updateTransforms(moved(t.scene));
    EXPECT_EQ(g.generation(), 1u);
    EXPECT_EQ(u.movedLights, 0);  // the spot light is real: placements move virtual objects only
    int virtualDraws = 0;
    for (size_t i = 0; i < g.draws().size(); ++i) {
        const DrawItem& a = drawsBefore[i];
        const DrawItem& b = g.draws()[i];
        if (a.origin == Origin::Virtual) {
            ++virtualDraws;
            EXPECT_GT(glm::length(b.bounds.center - a.bounds.center), 0.05f) << b.name;
            EXPECT_NEAR(b.bounds.radius, a.bounds.radius, 1e-5f) << b.name;
        } else {
            EXPECT_EQ(b.model, a.model) << b.name;
        }
    }
    EXPECT_EQ(u.movedDraws, virtualDraws);

    // The ISM pool moved with the objects: read it back and find every virtual point within its
    // draw's moved bounding sphere.
    std::vector<GpuSurfacePoint> pts(size_t(g.surfacePointCount()));
    glGetNamedBufferSubData(g.surfacePointBuffer().id(), 0,
                            GLsizeiptr(pts.size() * sizeof(GpuSurfacePoint)), pts.data());
    int virtualPoints = 0, inside = 0;
    for (const GpuSurfacePoint& p : pts) {
        if (p.isReal) continue;
        ++virtualPoints;
        for (const DrawItem& d : g.draws())
            if (d.origin == Origin::Virtual &&
                glm::length(p.position - d.bounds.center) <= d.bounds.radius * 1.001f) {
                ++inside;
                break;
            }
    }
    EXPECT_GT(virtualPoints, 10);  // the objects are small against the table
    EXPECT_EQ(inside, virtualPoints);
}

TEST_F(MovingObjects, TranslucentObjectIsNotMovedInPlace) {
    const auto dir = test::outputDir("moving_translucent");
    const Scene s = raytrace::test::translucentTestScene({}, dir);
    GpuScene g(s, 1024);
    Scene m = s;
    ScenePlacement p;
    p.moveU = 0.1;
    ASSERT_GT(applyPlacement(m, p, PlacementPlane{}), 0);
    const GpuScene::TransformUpdate u = g.updateTransforms(m);
    EXPECT_TRUE(u.translucentMoved);
    EXPECT_EQ(u.movedDraws, 0);
    EXPECT_EQ(g.generation(), 0u);
    EXPECT_EQ(g.draws()[0].model, glm::mat4(s.meshInstances()[0].world));
}

}  // namespace
}  // namespace mirage::render
