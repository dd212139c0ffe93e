// The reconstruction of real proxies and lights (render/reconstruction/) against exact truth:
// the bundled tabletop's real geometry (depth maps ray cast along `mirage synth`'s orbit), and a
// table lit by a known spot light. Fast: no reference rendering (the stereo step on rendered
// footage is measured by `mirage proxies --truth`, docs/results.md).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>

#include <gtest/gtest.h>

#include "core/image/ImageIO.h"
#include "core/scene/Scene.h"
#include "core/session/Session.h"
#include "render/raytrace/EmbreeDevice.h"
#include "render/raytrace/RayTracingScene.h"
#include "render/raytrace/SyntheticFootage.h"
#include "render/reconstruction/GeometryEvaluation.h"
#include "render/reconstruction/ProxyReconstruction.h"
#include "render/reconstruction/ProxyScene.h"
#include "render/reconstruction/ScanMap.h"
#include "tests/support/TestSupport.h"
#include "testscenes/FusedGeometryScene.h"

namespace mirage::reconstruction {
namespace {

namespace fs = std::filesystem;

BoardPlane tabletopPlane() {
    BoardPlane p;  // the board lies on the table top at y = 0, page +x along world +X
    p.point = {0, 0, 0};
    p.normal = {0, 1, 0};
    p.axisU = {1, 0, 0};
    p.halfU = 0.14, p.halfV = 0.1;
    return p;
}

const Scene& tabletop() {
    static const Scene s = loadScene(test::dataDir() / "scenes/tabletop/tabletop.gltf");
    return s;
}

// Exact depth maps of the scene's real meshes (the reference renderer's Embree scene) from the
// synthetic camera path's orbit, coloured with each surface's base colour.
std::vector<DepthView> exactViews(const Scene& scene, int count) {
    const raytrace::EmbreeDevice device;
    const raytrace::RayTracingScene rts(scene, raytrace::SceneSubset::RealOnly, device);
    const CameraIntrinsics K = raytrace::pinholeFromHorizontalFov(320, 240, 60.0);
    // `mirage synth --orbit-radius 0.7 --orbit-height 0.5`: wider than the default orbit (0.42 m,
    // 0.32 m), whose views never hold the block (it lies 50 degrees below their axes).
    raytrace::CameraPathOptions path;
    path.duration = 6.0;
    path.radius = 0.7, path.height = 0.5;
    std::vector<DepthView> views;
    for (int k = 0; k < count; ++k) {
        const double t = 3.0 * k / (count - 1);  // the orbit: the first half of the path
        DepthView v;
        v.T_world_camera = raytrace::cameraPathPose(path, t);
        v.fx = K.fx, v.fy = K.fy, v.cx = K.cx, v.cy = K.cy;
        v.depth = cv::Mat(K.height, K.width, CV_32F, 0.0f);
        v.bgr = cv::Mat(K.height, K.width, CV_8UC3, cv::Scalar::all(0));
        for (int y = 0; y < K.height; ++y)
            for (int x = 0; x < K.width; ++x) {
                const glm::dvec3 dCam =
                    glm::normalize(glm::dvec3((x - K.cx) / K.fx, (y - K.cy) / K.fy, 1.0));
                raytrace::SurfaceHit hit;
                if (!rts.intersect(glm::vec3(v.T_world_camera.translation),
                                   glm::vec3(v.T_world_camera.rotation * dCam), 100.0f, hit))
                    continue;
                v.depth.at<float>(y, x) = float(hit.t * dCam.z);
                const glm::vec4 c = rts.material(hit).gltf.baseColor;
                for (int ch = 0; ch < 3; ++ch)
                    v.bgr.at<cv::Vec3b>(y, x)[2 - ch] =
                        uchar(std::lround(255 * linearToSrgb(std::clamp(c[ch], 0.0f, 1.0f))));
            }
        views.push_back(std::move(v));
    }
    return views;
}

struct TabletopFixture : ::testing::Test {
    static const FusedGeometry& geometry() {
        static const FusedGeometry g = [] {
            Footage f;
            f.camera = raytrace::pinholeFromHorizontalFov(320, 240, 60.0);
            f.board = tabletopPlane();
            return reconstructGeometry(f, exactViews(tabletop(), 8));
        }();
        return g;
    }
};

TEST_F(TabletopFixture, TableExtentStaysOnTheTable) {
    const TableEstimate& t = geometry().table;
    // The orbit sees the table's middle; the extent never leaves the true top (1.2 x 0.8 m).
    EXPECT_LT(t.uMin, -0.25);
    EXPECT_GT(t.uMax, 0.25);
    EXPECT_GE(t.uMin, -0.63);
    EXPECT_LE(t.uMax, 0.63);
    EXPECT_GE(t.vMin, -0.43);
    EXPECT_LE(t.vMax, 0.43);
    EXPECT_LT(t.rmsHeightM, 0.002);
}

TEST_F(TabletopFixture, BookMugAndBlockAreRebuilt) {
    const FusedGeometry& g = geometry();
    for (const auto& o : g.objects)
        std::printf("%s at %.3f %.3f %.3f, %.3f x %.3f, %.3f tall\n", o.name.c_str(), o.centre.x,
                    o.centre.y, o.centre.z, o.sizeU, o.sizeV, o.heightM);
    ASSERT_EQ(g.objects.size(), 3u);
    for (const auto& o : g.objects) EXPECT_LE(o.indices.size() / 3, 1500u) << o.name;
    const GeometryScore s =
        evaluateGeometry(tabletop(), test::fusedGeometryScene(g), tabletopPlane());
    ASSERT_EQ(s.objects.size(), 3u);
    for (const ObjectScore& o : s.objects) {
        EXPECT_GE(o.completeness, 0.8) << o.name;
        EXPECT_LT(o.p95Mm, 15.0) << o.name;
    }
    EXPECT_GE(s.accuracy, 0.8);
}

// Must fail: a reconstruction that lost an object shows it as a large distance.
TEST_F(TabletopFixture, AMissingObjectShowsAsALargeDistance) {
    const FusedGeometry& g = geometry();
    ASSERT_FALSE(g.objects.empty());
    // The object nearest the true block (0.33, 0, 0.2).
    std::string nearest;
    double best = 1e9;
    for (const auto& o : g.objects)
        if (const double d = glm::length(o.centre - glm::dvec3(0.33, 0, 0.2)); d < best)
            best = d, nearest = o.name;
    ASSERT_LT(best, 0.02);
    const GeometryScore s =
        evaluateGeometry(tabletop(), test::fusedGeometryScene(g, nearest), tabletopPlane());
    for (const ObjectScore& o : s.objects)
        if (o.name == "block") {
            EXPECT_LT(o.completeness, 0.5);  // only its underside, on the table, is still near
            EXPECT_GT(o.p95Mm, 30.0);
        }
}

// A table lit by the environment and a spot light, observed exactly (radiance per cell); with
// `specular` > 0 it also reflects that share of the room's light (a glossy table).
FusedGeometry litTable(bool withSpot, FittedSpotLight& spot, glm::dvec3& environment,
                       glm::dvec3& albedo, double specular = 0.0) {
    FusedGeometry g;
    g.table.plane = tabletopPlane();
    g.table.uMin = -0.5, g.table.uMax = 0.5, g.table.vMin = -0.35, g.table.vMax = 0.35;
    g.tableCellM = 0.004;
    spot.position = {0.35, 0.95, 0.45};
    spot.direction = glm::normalize(-spot.position);
    spot.innerConeRad = 0.35, spot.outerConeRad = 0.55;
    spot.intensity = 1.6 * glm::dvec3(1.0, 0.95, 0.85);
    environment = {0.55, 0.56, 0.6};
    albedo = {0.35, 0.22, 0.12};
    const int cols = 250, rows = 175;
    g.tableColour = cv::Mat(rows, cols, CV_32FC3);
    g.tableObserved = cv::Mat(rows, cols, CV_8U, cv::Scalar(255));
    for (int y = 0; y < rows; ++y)
        for (int x = 0; x < cols; ++x) {
            const glm::dvec3 w = g.table.plane.toWorld(
                {g.table.uMin + (x + 0.5) * 0.004, g.table.vMin + (y + 0.5) * 0.004, 0});
            glm::dvec3 E = environment;
            if (withSpot) E += spot.intensity * spotGeometry(spot, w, {0, 1, 0});
            const glm::dvec3 L = (albedo * E + specular * environment) / 3.14159265358979;
            g.tableColour.at<cv::Vec3f>(y, x) = cv::Vec3f(float(L.x), float(L.y), float(L.z));
        }
    return g;
}

TEST(LightFit, RecoversTheSpotFromTheTable) {
    FittedSpotLight truth;
    glm::dvec3 environment, albedo;
    const FusedGeometry g = litTable(true, truth, environment, albedo);
    const LightingEstimate e = estimateLighting(g, environment);
    ASSERT_TRUE(e.spot.has_value());
    EXPECT_LT(glm::length(e.spot->position - truth.position), 0.02);
    EXPECT_LT(glm::degrees(std::acos(std::min(1.0, glm::dot(e.spot->direction, truth.direction)))),
              1.0);
    EXPECT_NEAR(e.spot->outerConeRad, truth.outerConeRad, 0.02);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(e.spot->intensity[c] / truth.intensity[c], 1.0, 0.05) << c;
        EXPECT_NEAR(e.tableAlbedo[c] / albedo[c], 1.0, 0.03) << c;
    }
}

// The renderers' GGX lobe of a dielectric: 0.04 head-on when fairly smooth (the quadrature
// resolves lobes of roughness 0.3 and up: the proxies are written at 0.8), more towards grazing and
// less when rough (masking); always a share between 0 and 1.
TEST(LightFit, DielectricSpecularAlbedoBehavesAsFresnelAndMasking) {
    EXPECT_NEAR(dielectricSpecularAlbedo(1.0, 0.3), 0.04, 0.004);
    EXPECT_GT(dielectricSpecularAlbedo(0.2, 0.3), dielectricSpecularAlbedo(0.9, 0.3));
    EXPECT_LT(dielectricSpecularAlbedo(0.6, 0.8), dielectricSpecularAlbedo(0.6, 0.3));
    for (double mu : {0.05, 0.3, 0.6, 1.0})
        for (double r : {0.3, 0.6, 0.8, 1.0}) {
            const double a = dielectricSpecularAlbedo(mu, r);
            EXPECT_TRUE(std::isfinite(a));
            EXPECT_GT(a, 0.0);
            EXPECT_LT(a, 1.0);
        }
}

// A glossy table reflects the room's light on top of its diffuse albedo (about the same from
// every view, so no quantile over the frames removes it): with the cameras' angle known, the
// written material's specular share is taken out and the albedo and the spot's intensity come
// out right; taken as albedo, the blue channel is 20 % too bright and the spot as much too weak.
TEST(LightFit, TheTablesReflectionOfTheRoomIsNotItsAlbedo) {
    FittedSpotLight truth;
    glm::dvec3 environment, albedo;
    const double viewCosine = 0.6;
    const double specular = dielectricSpecularAlbedo(viewCosine, 0.8);
    const FusedGeometry g = litTable(true, truth, environment, albedo, specular);
    LightFitOptions o;
    o.viewCosine = viewCosine;
    const LightingEstimate e = estimateLighting(g, environment, o);
    ASSERT_TRUE(e.spot.has_value());
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(e.tableAlbedo[c] / albedo[c], 1.0, 0.03) << c;
        EXPECT_NEAR(e.spot->intensity[c] / truth.intensity[c], 1.0, 0.05) << c;
    }
    o.viewCosine = 0;  // must fail: the reflection taken for albedo
    const LightingEstimate wrong = estimateLighting(g, environment, o);
    ASSERT_TRUE(wrong.spot.has_value());
    EXPECT_GT(wrong.tableAlbedo.z / albedo.z, 1.15);
    EXPECT_LT(wrong.spot->intensity.z / truth.intensity.z, 0.87);
}

TEST(LightFit, AnEvenlyLitTableHasNoSpot) {
    FittedSpotLight truth;
    glm::dvec3 environment, albedo;
    const FusedGeometry g = litTable(false, truth, environment, albedo);
    const LightingEstimate e = estimateLighting(g, environment);
    EXPECT_FALSE(e.spot.has_value());
    EXPECT_NEAR(e.tableAlbedo.x, albedo.x, 0.01);
}

Footage footageAt(const std::vector<Pose>& poses) {
    Footage f;
    f.camera = raytrace::pinholeFromHorizontalFov(320, 240, 60.0);
    f.board = tabletopPlane();
    for (size_t i = 0; i < poses.size(); ++i)
        f.frames.push_back({int(i), double(i), cv::Mat(240, 320, CV_8UC3), poses[i]});
    return f;
}

TEST(FootageCheck, PureRotationIsRefused) {
    std::vector<Pose> poses;
    for (int k = 0; k < 12; ++k)  // turning on the spot: a pan of 40 degrees
        poses.push_back(
            cameraLookingAt({0, 0.32, 0.42}, {0.4 * std::sin(0.06 * k - 0.3), 0, 0}, {0, 1, 0}));
    const Footage f = footageAt(poses);
    const FootageCheck c = checkFootage(f);
    EXPECT_FALSE(c.ok);
    EXPECT_NE(c.problem.find("pure rotation"), std::string::npos) << c.problem;
    EXPECT_THROW(reconstruct(f, std::nullopt), FootageRefused);
}

TEST(FootageCheck, TooFewFramesAreRefusedAndAnOrbitIsAccepted) {
    raytrace::CameraPathOptions path;
    std::vector<Pose> poses;
    for (int k = 0; k < 12; ++k) poses.push_back(raytrace::cameraPathPose(path, 0.125 * k));
    EXPECT_TRUE(checkFootage(footageAt(poses)).ok);
    poses.resize(5);
    const FootageCheck c = checkFootage(footageAt(poses));
    EXPECT_FALSE(c.ok);
    EXPECT_NE(c.problem.find("only 5 tracked frame"), std::string::npos) << c.problem;
}

TEST(StereoPairs, EachFrameGetsPartnersAtDifferentBaselines) {
    raytrace::CameraPathOptions path;  // `mirage synth`'s 6 s path: its orbit at 4 frames/s
    path.duration = 6.0;
    std::vector<Pose> poses;
    for (int k = 0; k < 12; ++k) poses.push_back(raytrace::cameraPathPose(path, 0.25 * k));
    const Footage f = footageAt(poses);
    StereoOptions o;
    o.partnersPerFrame = 1;
    const auto single = chooseStereoPairs(f, o);
    o.partnersPerFrame = 2;
    const auto pairs = chooseStereoPairs(f, o);
    // About twice the depth maps, never the same two frames twice (either order).
    EXPECT_GE(pairs.size(), single.size() * 3 / 2);
    std::set<std::pair<int, int>> seen;
    for (auto [a, b] : pairs) EXPECT_TRUE(seen.insert({std::min(a, b), std::max(a, b)}).second);
    // A frame in the middle of the orbit is matched at two different baselines.
    std::vector<double> baselines;
    for (auto [a, b] : pairs)
        if (a == 6 || b == 6)
            baselines.push_back(
                glm::length(poses[size_t(a)].translation - poses[size_t(b)].translation));
    ASSERT_GE(baselines.size(), 2u);
    std::sort(baselines.begin(), baselines.end());
    EXPECT_GT(baselines.back() - baselines.front(), 0.01);
    for (double b : baselines) {
        EXPECT_GE(b, o.minBaselineM);
        EXPECT_LE(b, o.maxBaselineM);
    }
}

// The scan seen from above: every camera the reconstruction used, where it stood (the cameras'
// side at the bottom, +u to the right), the table, each object and the spot; the caption states
// the arc and the angle down.
TEST(ScanMap, ShowsEveryCameraWhereItStoodWithTheTableObjectsAndSpot) {
    std::vector<Pose> poses;
    const int n = 10;
    for (int k = 0; k < n; ++k) {  // an arc of 60 degrees, 0.42 m out and 0.32 m up
        const double a = glm::radians(-30.0 + 60.0 * k / (n - 1));
        poses.push_back(
            cameraLookingAt({0.42 * std::sin(a), 0.32, 0.42 * std::cos(a)}, {0, 0, 0}, {0, 1, 0}));
    }
    const Footage f = footageAt(poses);
    Reconstruction r;
    r.check = checkFootage(f);
    r.geometry.table.plane = f.board;
    r.geometry.table.uMin = -0.6, r.geometry.table.uMax = 0.6;
    r.geometry.table.vMin = -0.4, r.geometry.table.vMax = 0.4;
    ProxyObject book;
    book.name = "real_object_1";
    book.centre = {0.31, 0, -0.25};
    for (double x : {0.2, 0.42})
        for (double z : {-0.33, -0.17}) book.positions.emplace_back(x, 0.04, z);
    r.geometry.objects.push_back(book);
    FittedSpotLight spot;
    spot.position = {0.35, 0.95, 0.45};
    spot.direction = glm::normalize(-spot.position);
    r.lighting.spot = spot;
    const std::string svg = scanMapSvg(f, r);
    ASSERT_EQ(svg.rfind("<svg", 0), 0u);
    EXPECT_NE(svg.find("</svg>"), std::string::npos);
    for (const char* cls : {"table", "board", "object", "spot"})
        EXPECT_NE(svg.find(std::string("class=\"") + cls + "\""), std::string::npos) << cls;
    std::vector<glm::dvec2> cameras;
    const std::regex camera(R"re(class="camera" cx="([-0-9.]+)" cy="([-0-9.]+)")re");
    for (auto it = std::sregex_iterator(svg.begin(), svg.end(), camera);
         it != std::sregex_iterator(); ++it)
        cameras.emplace_back(std::stod((*it)[1]), std::stod((*it)[2]));
    ASSERT_EQ(int(cameras.size()), n);
    const std::smatch board = [&] {
        std::smatch m;
        std::regex_search(svg, m,
                          std::regex(R"re(<text x="([-0-9.]+)" y="([-0-9.]+)"[^>]*>board)re"));
        return m;
    }();
    ASSERT_FALSE(board.empty());
    const double boardX = std::stod(board[1]), boardY = std::stod(board[2]);
    // The first camera stood left of the board (u < 0), the last right of it, all of them on
    // the near side (v < 0 for this board: below it on the map).
    EXPECT_LT(cameras.front().x, boardX - 50);
    EXPECT_GT(cameras.back().x, boardX + 50);
    for (const auto& c : cameras) EXPECT_GT(c.y, boardY + 50);
    EXPECT_NE(svg.find("10 frames"), std::string::npos);
    EXPECT_NE(svg.find("an arc of 60 degrees"), std::string::npos) << svg;
    EXPECT_NE(svg.find("looking 37-37 degrees down"), std::string::npos) << svg;
}

// The rebuilt scene written away from the virtual scene's folder: the files the virtual scene
// names are copied beside it (a scene names files in its own folder only), a different file of
// the same name already there is kept and the copy takes another name; the scene loads.
TEST(ProxyScene, FilesOfTheVirtualSceneAreCopiedBesideTheRebuiltOne) {
    const fs::path dir = test::outputDir("proxy_scene_copies");
    const fs::path collision = dir / "tabletop.bin";
    { std::ofstream(collision) << "not the tabletop's buffer"; }
    FittedSpotLight unused;
    glm::dvec3 environment, albedo;
    const FusedGeometry g = litTable(false, unused, environment, albedo);
    const LightingEstimate lighting = estimateLighting(g, environment);
    ProxySceneContent content;
    content.geometry = &g;
    content.lighting = &lighting;
    const fs::path out = dir / "scene.gltf";
    const ProxySceneSummary written =
        writeProxyScene(content, test::dataDir() / "scenes/tabletop/tabletop.gltf", out);
    std::set<std::string> copied;
    for (const std::string& f : written.copiedFiles) copied.insert(fs::path(f).filename());
    EXPECT_TRUE(copied.count("tabletop_1.bin")) << "the buffer under another name";
    EXPECT_FALSE(copied.count("tabletop.bin"));
    std::ifstream kept(collision);
    std::string text;
    std::getline(kept, text);
    EXPECT_EQ(text, "not the tabletop's buffer");  // nothing already there is written over
    const Scene scene = loadScene(out);
    EXPECT_FALSE(scene.nodes.empty());
    // Written again: the same copies are found and reused, none is added.
    const ProxySceneSummary again =
        writeProxyScene(content, test::dataDir() / "scenes/tabletop/tabletop.gltf", out);
    EXPECT_TRUE(again.copiedFiles.empty());
}

}  // namespace
}  // namespace mirage::reconstruction
