// Placing the virtual objects on the board plane: only virtual nodes move (the real proxies
// model the real world), moves stay in the plane, turns and scaling keep the objects' centre,
// and the placement file round-trips and refuses bad content.
#include <fstream>

#include <gtest/gtest.h>

#include "core/Error.h"
#include "core/scene/ScenePlacement.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

Scene tabletop() {
    return loadScene(test::dataDir() / "scenes" / "tabletop" / "tabletop.gltf");
}

// The table plane of the tabletop scene: y = 0, normal +Y, board +X = world +X.
PlacementPlane tablePlane() {
    return {{0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {1.0, 0.0, 0.0}};
}

TEST(ScenePlacement, MovesOnlyVirtualNodesWithinThePlane) {
    const Scene before = tabletop();
    Scene after = before;
    ScenePlacement p;
    p.moveU = 0.10;
    p.moveV = -0.05;
    EXPECT_GT(applyPlacement(after, p, tablePlane()), 0);
    const auto a = before.meshInstances(), b = after.meshInstances();
    ASSERT_EQ(a.size(), b.size());
    int virtualCount = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        const glm::dvec3 d = glm::dvec3(b[i].world[3]) - glm::dvec3(a[i].world[3]);
        if (a[i].origin == Origin::Virtual) {
            ++virtualCount;
            // u = +X, v = normal x u = +Y x +X = -Z: -0.05 along v is +0.05 along Z.
            EXPECT_NEAR(d.x, 0.10, 1e-12);
            EXPECT_NEAR(d.y, 0.0, 1e-12);
            EXPECT_NEAR(d.z, 0.05, 1e-12);
        } else {
            EXPECT_EQ(glm::length(d), 0.0) << "a real proxy moved";
        }
    }
    EXPECT_GT(virtualCount, 0);
    const auto la = before.lightInstances(), lb = after.lightInstances();
    for (size_t i = 0; i < la.size(); ++i) {
        if (la[i].origin == Origin::Real) {
            EXPECT_EQ(la[i].position, lb[i].position);
        }
    }
}

TEST(ScenePlacement, TurnAndScaleKeepTheCentreOnThePlane) {
    const Scene before = tabletop();
    const glm::dvec3 c0 = virtualCentre(before);
    Scene turned = before;
    ScenePlacement p;
    p.turnDeg = 90;
    applyPlacement(turned, p, tablePlane());
    const glm::dvec3 c1 = virtualCentre(turned);
    EXPECT_NEAR(c1.x, c0.x, 1e-9);
    EXPECT_NEAR(c1.z, c0.z, 1e-9);
    EXPECT_NEAR(c1.y, c0.y, 1e-9);
    // Each virtual instance turned by 90 degrees about +Y around the centre's foot on the plane.
    const auto a = before.meshInstances(), b = turned.meshInstances();
    for (size_t i = 0; i < a.size(); ++i) {
        if (a[i].origin != Origin::Virtual) continue;
        const glm::dvec3 ra = glm::dvec3(a[i].world[3]) - glm::dvec3(c0.x, 0, c0.z);
        const glm::dvec3 rb = glm::dvec3(b[i].world[3]) - glm::dvec3(c0.x, 0, c0.z);
        // Counter-clockwise seen from +Y: (x, z) -> (z, -x).
        EXPECT_NEAR(rb.x, ra.z, 1e-9);
        EXPECT_NEAR(rb.z, -ra.x, 1e-9);
        EXPECT_NEAR(rb.y, ra.y, 1e-9);
    }
    Scene scaled = before;
    ScenePlacement s;
    s.scale = 2;
    applyPlacement(scaled, s, tablePlane());
    const auto c = scaled.meshInstances();
    for (size_t i = 0; i < a.size(); ++i) {
        if (a[i].origin != Origin::Virtual) continue;
        const glm::dvec3 foot(c0.x, 0, c0.z);
        EXPECT_NEAR(glm::length(glm::dvec3(c[i].world[3]) - foot),
                    2 * glm::length(glm::dvec3(a[i].world[3]) - foot), 1e-9);
    }
}

// Dragging with the mouse: the pixel where a plane point is seen maps back to that point, and a
// drag between two pixels moves by the in-plane offset of their points.
TEST(ScenePlacement, PixelOnPlaneInvertsTheProjection) {
    CameraIntrinsics cam;
    cam.width = 640;
    cam.height = 480;
    cam.fx = cam.fy = 554.256;
    cam.cx = 319.5;
    cam.cy = 239.5;
    cam.distortion = {-0.1, 0.02, 0.001, -0.002, 0.0};
    // A camera 0.4 m above the table looking down at 45 degrees (OpenCV axes: +Z forward).
    const glm::dvec3 eye(0.1, 0.4, 0.5);
    const glm::dvec3 fwd = glm::normalize(glm::dvec3(0.0, -0.4, -0.4));
    const glm::dvec3 right = glm::normalize(glm::cross(fwd, glm::dvec3(0, 1, 0)));
    const glm::dvec3 down = glm::cross(fwd, right);
    const Pose T = Pose::fromRotationTranslation(glm::dmat3(right, down, fwd), eye);
    const PlacementPlane plane = tablePlane();
    for (const glm::dvec3 w :
         {glm::dvec3(0.1, 0, 0.1), glm::dvec3(-0.05, 0, 0.0), glm::dvec3(0.2, 0, 0.05)}) {
        const glm::dvec3 pc = glm::transpose(T.rotationMatrix()) * (w - T.translation);
        const std::optional<glm::dvec2> px = cam.project(pc);
        ASSERT_TRUE(px.has_value());
        const std::optional<glm::dvec3> back = pixelOnPlane(cam, T, *px, plane);
        ASSERT_TRUE(back.has_value());
        EXPECT_NEAR(glm::length(*back - w), 0.0, 1e-6);
    }
    const glm::dvec2 m = inPlaneMove({0, 0, 0}, {0.03, 0, -0.02}, plane);
    EXPECT_NEAR(m.x, 0.03, 1e-12);
    EXPECT_NEAR(m.y, 0.02, 1e-12);  // v = +Y x +X = -Z
    // A pixel whose ray points above the horizon never meets the table.
    EXPECT_FALSE(pixelOnPlane(cam,
                              Pose::fromRotationTranslation(glm::dmat3(right, -down, -fwd), eye),
                              {320, 240}, plane)
                     .has_value());
}

TEST(ScenePlacement, FileRoundTripsAndBadContentIsRefused) {
    const auto dir = test::outputDir("scene_placement");
    const auto file = dir / "scene.gltf.placement.json";
    EXPECT_FALSE(loadPlacement(file).has_value());  // none yet: the scene as modelled
    ScenePlacement p;
    p.moveU = 0.123456789;
    p.moveV = -0.5;
    p.turnDeg = 33.3;
    p.scale = 0.8;
    savePlacement(file, p);
    EXPECT_EQ(loadPlacement(file), p);
    EXPECT_EQ(placementPath("/x/scene.gltf"), "/x/scene.gltf.placement.json");
    auto bad = [&](const std::string& text, const std::string& what) {
        std::ofstream(file) << text;
        try {
            loadPlacement(file);
            ADD_FAILURE() << "accepted: " << text;
        } catch (const FileError& e) {
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
        }
    };
    bad("{", "not valid JSON");
    bad(R"({"format": "other", "version": 1})", "field 'format'");
    bad(R"({"format": "mirage-placement", "version": 2})", "field 'version'");
    bad(R"({"format": "mirage-placement", "version": 1, "scale": 0})", "field 'scale'");
    bad(R"({"format": "mirage-placement", "version": 1, "turn_deg": "x"})", "field 'turn_deg'");
}

}  // namespace
}  // namespace mirage
