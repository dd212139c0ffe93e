// Space carving against the table's plane (render/reconstruction/SpaceCarving.h) on footage of
// plain, untextured objects: the bundled tabletop's real meshes ray cast along the wide orbit of
// `mirage synth` and shaded with one colour per material (a directional light, no texture), so
// that photo-consistency stereo has nothing to match on the objects' faces. Hard cases: a glossy
// object (a highlight that moves with the view), an object standing on the board, a frame
// whose pose is wrong.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>
#include <glm/gtc/quaternion.hpp>

#include <opencv2/imgproc.hpp>

#include "core/image/ImageIO.h"
#include "core/scene/Scene.h"
#include "render/raytrace/EmbreeDevice.h"
#include "render/raytrace/RayTracingScene.h"
#include "render/raytrace/SyntheticFootage.h"
#include "render/reconstruction/GeometryEvaluation.h"
#include "render/reconstruction/ProxyGeometry.h"
#include "tests/support/TestSupport.h"
#include "testscenes/FusedGeometryScene.h"

namespace mirage::reconstruction {
namespace {

BoardPlane tablePlane() {
    BoardPlane p;  // the board lies on the table top at y = 0, page +x along world +X
    p.halfU = 0.14, p.halfV = 0.1;
    return p;
}

Scene tabletopScene() {
    return loadScene(test::dataDir() / "scenes/tabletop/tabletop.gltf");
}

int nodeNamed(const Scene& s, const std::string& name) {
    for (size_t i = 0; i < s.nodes.size(); ++i)
        if (s.nodes[i].name == name) return int(i);
    throw Error("no node " + name);
}

struct Shading {
    double specular = 0;  // white Phong highlight on materials rougher than 0.5 left out
    // A glossy table top: the broad reflection of a bright window behind the table, white, in
    // the views whose mirror direction meets it.
    double tableGlare = 0;
};

const glm::dvec3 kLight = glm::normalize(glm::dvec3(0.3, 1.0, 0.4));
const glm::dvec3 kWindow = glm::normalize(glm::dvec3(-0.2, 0.6, -0.8));

// The footage's colour of a surface without its highlights: the base colour times
// (0.35 + 0.65 cos) for the light from above.
glm::dvec3 diffuseShade(const glm::dvec3& base, const glm::dvec3& n) {
    return base * (0.35 + 0.65 * std::max(0.0, glm::dot(n, kLight)));
}

// Posed frames of the scene's real meshes along `mirage synth`'s wide orbit (0.7 m radius: the
// default orbit never holds the block), alternately 0.5 m and 0.25 m high (35 and 20 degrees
// down: the scan docs/reconstruction.md asks for; from one height the space over a plain top is
// hidden behind the top itself), 320x240, sRGB. A surface's colour is its base colour times
// (0.35 + 0.65 cos) for a light from above; the glossy ones add a Phong highlight.
Footage renderFootage(const Scene& scene, int count, const Shading& shading = {}) {
    const raytrace::EmbreeDevice device;
    const raytrace::RayTracingScene rts(scene, raytrace::SceneSubset::RealOnly, device);
    Footage f;
    f.camera = raytrace::pinholeFromHorizontalFov(320, 240, 60.0);
    f.board = tablePlane();
    const CameraIntrinsics& K = f.camera;
    raytrace::CameraPathOptions path;
    path.duration = 6.0;
    path.radius = 0.7;
    for (int k = 0; k < count; ++k) {
        PosedFrame frame;
        frame.index = k;
        frame.t = 3.0 * k / (count - 1);  // the orbit: the first half of the path
        path.height = k % 2 ? 0.25 : 0.5;
        frame.T_world_camera = raytrace::cameraPathPose(path, frame.t);
        frame.bgr = cv::Mat(K.height, K.width, CV_8UC3, cv::Scalar::all(0));
        const glm::dvec3 eye = frame.T_world_camera.translation;
        for (int y = 0; y < K.height; ++y)
            for (int x = 0; x < K.width; ++x) {
                const glm::dvec3 d =
                    glm::normalize(frame.T_world_camera.rotation *
                                   glm::dvec3((x - K.cx) / K.fx, (y - K.cy) / K.fy, 1.0));
                raytrace::SurfaceHit hit;
                if (!rts.intersect(glm::vec3(eye), glm::vec3(d), 100.0f, hit)) continue;
                const Material& m = rts.material(hit).gltf;
                const glm::dvec3 n(hit.ns);
                glm::dvec3 c = diffuseShade(glm::dvec3(m.baseColor), n);
                if (m.roughness < 0.5f && shading.specular > 0) {
                    const glm::dvec3 r = glm::reflect(-kLight, n);
                    c += shading.specular * std::pow(std::max(0.0, glm::dot(r, -d)), 40.0);
                }
                if (shading.tableGlare > 0 && m.name == "table wood")
                    c += shading.tableGlare *
                         std::pow(std::max(0.0, glm::dot(glm::reflect(d, n), kWindow)), 16.0);
                for (int ch = 0; ch < 3; ++ch)
                    frame.bgr.at<cv::Vec3b>(y, x)[2 - ch] =
                        uchar(std::lround(255 * linearToSrgb(float(std::clamp(c[ch], 0.0, 1.0)))));
            }
        f.frames.push_back(std::move(frame));
    }
    return f;
}

// Exact depth where the footage has edges (a colour step of more than 2 % between neighbours),
// none on the plain faces: what photo-consistency stereo gives on such footage at best.
std::vector<DepthView> depthAtEdges(const Scene& scene, const Footage& f) {
    const raytrace::EmbreeDevice device;
    const raytrace::RayTracingScene rts(scene, raytrace::SceneSubset::RealOnly, device);
    const CameraIntrinsics& K = f.camera;
    std::vector<DepthView> views;
    for (size_t k = 0; k < f.frames.size(); k += 2) {
        DepthView v;
        v.T_world_camera = f.frames[k].T_world_camera;
        v.fx = K.fx, v.fy = K.fy, v.cx = K.cx, v.cy = K.cy;
        v.bgr = f.frames[k].bgr;
        v.depth = cv::Mat(K.height, K.width, CV_32F, 0.0f);
        cv::Mat grey, gradient;
        cv::cvtColor(v.bgr, grey, cv::COLOR_BGR2GRAY);
        cv::morphologyEx(grey, gradient, cv::MORPH_GRADIENT, cv::Mat());
        for (int y = 0; y < K.height; ++y)
            for (int x = 0; x < K.width; ++x) {
                if (gradient.at<uchar>(y, x) < 5) continue;
                const glm::dvec3 dc((x - K.cx) / K.fx, (y - K.cy) / K.fy, 1.0);
                const glm::dvec3 d = glm::normalize(v.T_world_camera.rotation * dc);
                raytrace::SurfaceHit hit;
                if (rts.intersect(glm::vec3(v.T_world_camera.translation), glm::vec3(d), 100.0f,
                                  hit))
                    v.depth.at<float>(y, x) = float(hit.t / glm::length(dc));
            }
        views.push_back(std::move(v));
    }
    return views;
}

struct Carved {
    FusedGeometry geometry;
    GeometryScore score;
};

Carved carveAndScore(const Scene& truth, const Footage& f, const CarvingOptions& o = {}) {
    const CarvedHeights carved = carveAbovePlane(f, o);
    Carved c;
    c.geometry = reconstructGeometry(f, depthAtEdges(truth, f), {}, o.enabled ? &carved : nullptr);
    c.score = evaluateGeometry(truth, test::fusedGeometryScene(c.geometry), f.board);
    for (const auto& s : c.score.objects)
        std::printf("%s: %.1f %% within 1 cm (mean %.1f mm, p95 %.1f mm)\n", s.name.c_str(),
                    100 * s.completeness, s.meanMm, s.p95Mm);
    std::printf("rebuilt above the table within 1 cm: %.1f %%, %zu objects, %.2f s\n",
                100 * c.score.accuracy, c.geometry.objects.size(), carved.seconds);
    return c;
}

// Shares of each true object's surface within 1 cm of the rebuilt geometry, at least. What this
// footage allows (docs/results.md): the book's plain top is cut by the fused edges; the mug and
// the block keep part of the wedge over their tops and their unseen backs.
struct Minimum {
    double book = 0.85, mug = 0.7, block = 0.4;
};

void expectRebuilt(const GeometryScore& s, const Minimum& m = {}) {
    ASSERT_EQ(s.objects.size(), 3u);
    for (const ObjectScore& o : s.objects)
        EXPECT_GE(o.completeness, o.name == "book"  ? m.book
                                  : o.name == "mug" ? m.mug
                                                    : m.block)
            << o.name;
}

TEST(SpaceCarving, PlainObjectsAreRebuiltFromTheirSilhouettes) {
    const Scene truth = tabletopScene();
    const Carved c = carveAndScore(truth, renderFootage(truth, 16));
    expectRebuilt(c.score);
    EXPECT_GE(c.score.accuracy, 0.4);
}

// Without the carving, the same footage and (object-free) fused surface give no object at all.
TEST(SpaceCarving, WithoutCarvingTheObjectsAreMissing) {
    const Scene truth = tabletopScene();
    CarvingOptions off;
    off.enabled = false;
    const Carved c = carveAndScore(truth, renderFootage(truth, 16), off);
    EXPECT_TRUE(c.geometry.objects.empty());
    for (const ObjectScore& o : c.score.objects) EXPECT_LT(o.completeness, 0.5) << o.name;
}

// The mug (roughness 0.3) shows a white highlight that moves with the view: it never matches
// the table, so it never carves.
TEST(SpaceCarving, AGlossyObjectIsRebuilt) {
    const Scene truth = tabletopScene();
    Shading glossy;
    glossy.specular = 3.0;
    const Carved c = carveAndScore(truth, renderFootage(truth, 16, glossy));
    expectRebuilt(c.score);
    EXPECT_GE(c.score.accuracy, 0.4);
}

// The block stands on the board, hiding part of it: the board's cells under it are covered in
// every view (not the paper's colour), so it is still found as an object, but rebuilt less
// well than on the wood (the paper's reference is grey: the block's shaded faces pass for the
// board's paper and tags in a share of the frames).
TEST(SpaceCarving, AnObjectOnTheBoardIsRebuilt) {
    Scene truth = tabletopScene();
    Node& block = truth.nodes[size_t(nodeNamed(truth, "block"))];
    block.world[3] = glm::dvec4(0.06, 0.0, 0.03, 1.0);
    block.local = block.world;
    const Carved c = carveAndScore(truth, renderFootage(truth, 16));
    EXPECT_GE(c.geometry.objects.size(), 3u);
    Minimum m;
    m.block = 0.2;
    expectRebuilt(c.score, m);
}

// One frame's pose is 3 degrees off (a tracker's error it did not flag): alone it cannot carve
// (two frames must see the table through a voxel), so the objects survive it; with one vote
// enough, the same frame cuts into them.
TEST(SpaceCarving, OneMistrackedFrameDoesNotCarveTheObjects) {
    const Scene truth = tabletopScene();
    Footage f = renderFootage(truth, 16);
    Pose& wrong = f.frames[7].T_world_camera;
    wrong.rotation = glm::angleAxis(glm::radians(3.0), glm::dvec3(0, 1, 0)) * wrong.rotation;
    const Carved robust = carveAndScore(truth, f);
    expectRebuilt(robust.score);
    CarvingOptions oneVote;
    oneVote.minPlaneVotes = 1;
    const Carved fragile = carveAndScore(truth, f, oneVote);
    double worst = 1.0;
    for (const ObjectScore& o : fragile.score.objects) worst = std::min(worst, o.completeness);
    EXPECT_LT(worst, 0.5);
}

// Seen through the carving, the table reaches as far as the frames see its colour; the fused
// surface, with depth only at the footage's edges (none on the plain wood), holds little of it.
TEST(SpaceCarving, TheTableReachesWhereTheFramesSeeIt) {
    const Scene truth = tabletopScene();
    const Footage f = renderFootage(truth, 16);
    const CarvedHeights carved = carveAbovePlane(f);
    const FusedGeometry with = reconstructGeometry(f, depthAtEdges(truth, f), {}, &carved);
    const FusedGeometry without = reconstructGeometry(f, depthAtEdges(truth, f), {}, nullptr);
    auto area = [](const TableEstimate& t) { return (t.uMax - t.uMin) * (t.vMax - t.vMin); };
    std::printf("table %.2f x %.2f m with the carving, %.2f x %.2f m without (true 1.2 x 0.8)\n",
                with.table.uMax - with.table.uMin, with.table.vMax - with.table.vMin,
                without.table.uMax - without.table.uMin, without.table.vMax - without.table.vMin);
    // Not onto the floor (0.75 m below, another colour). The table's 4 cm thick sides, of its
    // colour, lie on the rays that meet the plane just beyond its edges: from 20-35 degrees down
    // they reach the plane up to 6 cm further.
    const double side = 0.06;
    EXPECT_GE(with.table.uMin, -0.6 - side);
    EXPECT_LE(with.table.uMax, 0.6 + side);
    EXPECT_GE(with.table.vMin, -0.4 - side);
    EXPECT_LE(with.table.vMax, 0.4 + side);
    EXPECT_GE(area(with.table), 0.8 * 1.2 * 0.8);
    EXPECT_LT(area(without.table), 0.5 * area(with.table));  // must fail without the carving
}

// A glossy table shows a window's reflection in the views that face it (about half of them). The
// light fit and the albedo take a low quantile of each cell's table-coloured samples, which stays
// on the wood's diffuse colour; the median (the carving's own colour) rises with the glare.
TEST(SpaceCarving, TheTablesDiffuseColourLeavesItsGlareOut) {
    const Scene truth = tabletopScene();
    Shading glossy;
    glossy.tableGlare = 0.25;
    const CarvedHeights carved = carveAbovePlane(renderFootage(truth, 16, glossy));
    const PlaneAppearance& a = carved.plane;
    const glm::dvec3 wood = diffuseShade({0.35, 0.22, 0.12}, {0, 1, 0});
    std::vector<double> diffuseError, medianError;
    for (int y = 0; y < a.kind.rows; ++y)
        for (int x = 0; x < a.kind.cols; ++x) {
            const double u = a.u0 + (x + 0.5) * a.cell, v = a.v0 + (y + 0.5) * a.cell;
            const bool onBoard = std::abs(u) < 0.16 && std::abs(v) < 0.12;
            if (a.kind.at<uchar>(y, x) != PlaneAppearance::Table || onBoard)
                continue;  // the board's paper is another colour
            auto error = [&](const cv::Vec3f& c) {
                return std::abs(double(c[0] + c[1] + c[2]) / (wood.x + wood.y + wood.z) - 1.0);
            };
            diffuseError.push_back(error(a.diffuseColour.at<cv::Vec3f>(y, x)));
            medianError.push_back(error(a.colour.at<cv::Vec3f>(y, x)));
        }
    ASSERT_GT(diffuseError.size(), 5000u);
    auto median = [](std::vector<double> v) {
        std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
        return v[v.size() / 2];
    };
    std::printf("table cells' brightness error, median over %zu cells: diffuse %.3f, median %.3f\n",
                diffuseError.size(), median(diffuseError), median(medianError));
    // The lowest tenth of a cell's samples still meets the glare's wide skirt in some cells.
    EXPECT_LT(median(diffuseError), 0.08);
    EXPECT_GT(median(medianError), 0.2);  // must fail: the median colour holds the glare
}

}  // namespace
}  // namespace mirage::reconstruction
