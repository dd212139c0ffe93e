// Reflected-scene impostors (render/passes/impostor) against exact Embree ray casts, the plain
// cube-map baseline, and the hard cases: rays leaving the scene, grazing rays, rays parallel to an
// impostor plane. Small resolutions and ray counts so the whole file stays well under 30 s.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "core/gl/Context.h"
#include "render/GpuScene.h"
#include "render/Renderer.h"
#include "render/passes/impostor/ImpostorAccuracy.h"
#include "render/passes/impostor/ImpostorPass.h"
#include "render/raytrace/EmbreeDevice.h"
#include "render/raytrace/RayTracingScene.h"
#include "testscenes/ImpostorTestScene.h"

namespace mirage::render {
namespace {

bool finite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

class ImpostorTrace : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        context_ = std::make_unique<gl::Context>(gl::Context::headless());
        device_ = std::make_unique<raytrace::EmbreeDevice>("threads=2");
        for (int room = 0; room < 2; ++room) {
            scenes_[room] = std::make_unique<Scene>(test::impostorTestScene(room == 1, 16));
            gpu_[room] = std::make_unique<GpuScene>(*scenes_[room], 64);
            exact_[room] = std::make_unique<raytrace::RayTracingScene>(
                *scenes_[room], raytrace::SceneSubset::All, *device_);
        }
    }
    static void TearDownTestSuite() {
        for (int room = 0; room < 2; ++room) {
            exact_[room].reset();
            gpu_[room].reset();
            scenes_[room].reset();
        }
        device_.reset();
        context_.reset();
    }
    static RendererOptions options(int res, int steps, bool baseline) {
        RendererOptions o;
        o.impostor.resolution = res;
        o.impostor.refineSteps = steps;
        o.impostor.cubeMapBaseline = baseline;
        return o;
    }
    static std::unique_ptr<gl::Context> context_;
    static std::unique_ptr<raytrace::EmbreeDevice> device_;
    static std::unique_ptr<Scene> scenes_[2];
    static std::unique_ptr<GpuScene> gpu_[2];
    static std::unique_ptr<raytrace::RayTracingScene> exact_[2];
};
std::unique_ptr<gl::Context> ImpostorTrace::context_;
std::unique_ptr<raytrace::EmbreeDevice> ImpostorTrace::device_;
std::unique_ptr<Scene> ImpostorTrace::scenes_[2];
std::unique_ptr<GpuScene> ImpostorTrace::gpu_[2];
std::unique_ptr<raytrace::RayTracingScene> ImpostorTrace::exact_[2];

TEST_F(ImpostorTrace, ClassifiesPlanesBillboardsAndEnclosingItems) {
    ImpostorPass pass;
    ASSERT_TRUE(pass.update(*gpu_[1], options(32, 2, false)));
    const ImpostorBuildStats& s = pass.buildStats();
    EXPECT_EQ(s.objects, 2);
    // Each sphere sees the floor as a plane; the room encloses both; the other five items
    // (two boxes, the green sphere, the other specular sphere... ) are billboards.
    EXPECT_EQ(s.planes, 2);
    EXPECT_EQ(s.enclosingItems, 2);
    EXPECT_EQ(s.billboards, 2 * 4);
    EXPECT_GT(s.textureBytes, 0u);
    // Cached: the same scene and resolution do not rebuild; a new resolution does.
    EXPECT_FALSE(pass.update(*gpu_[1], options(32, 4, true)));
    EXPECT_TRUE(pass.update(*gpu_[1], options(16, 4, true)));
}

// The artifact Popescu et al. fix: a cube map from the centre is exact only for rays through the
// centre, so a NEAR object (the red box, 10 cm from the mirror) is reflected in the wrong place.
TEST_F(ImpostorTrace, ImpostorsBeatTheCubeMapOnANearObject) {
    const auto rays = sampleSpecularSurfaceRays(*scenes_[0], *gpu_[0], 1500, 7);
    const auto exact = castExact(rays, *gpu_[0], *exact_[0]);
    std::vector<ImpostorRay> nearRays;
    std::vector<ExactHit> nearExact;
    for (size_t i = 0; i < rays.size(); ++i)
        if (rays[i].specularSlot == 0 && exact[i].hit && exact[i].position.x > 0.34f &&
            exact[i].position.x < 0.56f && exact[i].position.y > 0.001f &&
            std::abs(exact[i].position.z) < 0.11f) {
            nearRays.push_back(rays[i]);
            nearExact.push_back(exact[i]);
        }
    ASSERT_GT(nearRays.size(), 40u);
    ImpostorPass pass;
    pass.update(*gpu_[0], options(128, 4, true));
    const ImpostorAccuracy cube = compareHits(pass.trace(nearRays), nearExact);
    pass.update(*gpu_[0], options(128, 4, false));
    const ImpostorAccuracy imp = compareHits(pass.trace(nearRays), nearExact);
    EXPECT_GT(imp.hitMissAgreement, 0.9);
    EXPECT_LT(imp.medianErrorMm, 5.0);
    EXPECT_GT(cube.medianErrorMm, 4.0 * imp.medianErrorMm)
        << "cube median " << cube.medianErrorMm << " mm, impostors " << imp.medianErrorMm;
    EXPECT_GT(cube.falseHit + cube.falseMiss + cube.bothHit, 0);
}

TEST_F(ImpostorTrace, RaysThatLeaveTheSceneMiss) {
    for (int room = 0; room < 2; ++room) {
        ImpostorPass pass;
        for (bool baseline : {false, true}) {
            pass.update(*gpu_[room], options(64, 4, baseline));
            // Straight up from the top of each sphere, and steeply up past the walls' top edge.
            std::vector<ImpostorRay> rays = {
                {{0.0f, 0.5001f, 0.0f}, {0.0f, 1.0f, 0.0f}, 0},
                {{0.9f, 0.3001f, 0.8f}, {0.0f, 1.0f, 0.0f}, 1},
                {{0.0f, 0.5001f, 0.0f}, glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f)), 0}};
            for (const ImpostorHit& h : pass.trace(rays))
                EXPECT_FALSE(h.hit) << "room " << room << " baseline " << baseline;
        }
    }
}

TEST_F(ImpostorTrace, GrazingAndParallelRaysGiveNoNaN) {
    ImpostorPass pass;
    std::vector<ImpostorRay> rays;
    const glm::vec3 c(0.0f, 0.25f, 0.0f);
    // Parallel to the floor plane, exactly and nearly; along the axes (parallel to box faces and
    // to impostor planes whose axes are axis-aligned); at the sphere's silhouette; degenerate.
    const glm::vec3 dirs[] = {{1, 0, 0},  {0, 0, 1},         {-1, 0, 0},
                              {0, 0, -1}, {1, 1e-7f, 0},     {0.7071f, -1e-6f, 0.7071f},
                              {0, -1, 0}, {1, -1e-3f, 1e-4f}};
    for (const glm::vec3& d : dirs)
        for (int k = 0; k < 8; ++k) {
            const float a = float(k) * 0.785f;
            const glm::vec3 n(std::cos(a), 0.0f, std::sin(a));
            rays.push_back({c + n * 0.2501f + glm::vec3(0, -0.2499f, 0), glm::normalize(d), 0});
            rays.push_back({c + n * 0.2501f, glm::normalize(d), 0});
        }
    // Rays parallel to each billboard plane of the mirror: perpendicular to centre->item.
    for (const glm::vec3& item : {glm::vec3(0.45f, 0.15f, 0.0f), glm::vec3(-1.3f, 0.3f, 0.7f),
                                  glm::vec3(0.2f, 0.2f, -1.0f), glm::vec3(0.9f, 0.15f, 0.8f)}) {
        const glm::vec3 w = glm::normalize(item - c);
        const glm::vec3 u = glm::normalize(glm::cross(w, glm::vec3(0, 1, 0)));
        rays.push_back({c + w * 0.2501f, u, 0});
        rays.push_back({c + w * 0.2501f, -u, 0});
        rays.push_back({c + w * 0.2501f, glm::normalize(glm::cross(w, u)), 0});
    }
    rays.push_back({c, glm::vec3(0.0f), 0});       // zero direction: no hit, no NaN
    rays.push_back({c, glm::vec3(1, 0, 0), 7});    // slot out of range
    rays.push_back({c, glm::vec3(NAN, 0, 1), 0});  // NaN input
    for (int room = 0; room < 2; ++room)
        for (int steps : {0, 1, 8})
            for (bool baseline : {false, true}) {
                pass.update(*gpu_[room], options(64, steps, baseline));
                const auto hits = pass.trace(rays);
                for (size_t i = 0; i < hits.size(); ++i) {
                    EXPECT_TRUE(finite(hits[i].position) && finite(hits[i].normal) &&
                                finite(hits[i].albedo) && finite(hits[i].emissive) &&
                                std::isfinite(hits[i].roughness) && std::isfinite(hits[i].metallic))
                        << "ray " << i << " room " << room << " steps " << steps;
                    if (hits[i].hit) {
                        EXPECT_NEAR(glm::length(hits[i].normal), 1.0f, 1e-3f);
                        EXPECT_TRUE(hits[i].origin == kOriginReal ||
                                    hits[i].origin == kOriginVirtual);
                    }
                }
                const size_t n = hits.size();
                EXPECT_FALSE(hits[n - 1].hit || hits[n - 2].hit || hits[n - 3].hit);
            }
}

// Refinement matters, and the accuracy bound is a real bound: 0 steps fails what 8 steps meet.
TEST_F(ImpostorTrace, RefinementReducesErrorAndTheBoundCanFail) {
    const auto rays = sampleSpecularSurfaceRays(*scenes_[1], *gpu_[1], 600, 11);
    const auto exact = castExact(rays, *gpu_[1], *exact_[1]);
    ImpostorPass pass;
    pass.update(*gpu_[1], options(128, 0, false));
    const ImpostorAccuracy a0 = compareHits(pass.trace(rays), exact);
    pass.update(*gpu_[1], options(128, 8, false));
    const ImpostorAccuracy a8 = compareHits(pass.trace(rays), exact);
    EXPECT_LT(a8.meanErrorMm, 0.5 * a0.meanErrorMm)
        << "0 steps " << a0.meanErrorMm << " mm, 8 steps " << a8.meanErrorMm << " mm";
    const double bound = 3.0 * a8.p90ErrorMm + 1.0;
    EXPECT_LT(a8.p90ErrorMm, bound);
    EXPECT_GT(a0.p90ErrorMm, bound) << "the bound would not catch unrefined impostors";
    // Overall agreement with the exact ray casts (the room encloses both objects).
    EXPECT_GT(a8.hitMissAgreement, 0.95);
    EXPECT_GT(a8.originAgreement, 0.95);
    EXPECT_LT(a8.medianErrorMm, 10.0);
}

// Large geometry UNDER the object that is not a single plane (a thick table top: a box the
// mirror stands on) cannot be a billboard around the table; it goes to the enclosing cube map and
// is searched along the ray there. Rays from the lower half of the mirror must hit its top face.
TEST_F(ImpostorTrace, ThickTableUnderTheObjectIsTracedExactly) {
    Scene s;
    const int wood = test::addMaterial(s, glm::vec3(0.5f, 0.35f, 0.2f));
    const int mirror = test::addMaterial(s, glm::vec3(0.95f), 0.0f, 1.0f);
    test::addBox(s, "table", {-1.0f, -0.05f, -0.6f}, {1.0f, 0.0f, 0.6f}, wood, Origin::Real);
    test::addUvSphere(s, "mirror", {0.0f, 0.25f, 0.0f}, 0.25f, mirror, Origin::Virtual, 16, 2 * 16);
    GpuScene gpu(s, 64);
    raytrace::RayTracingScene rt(s, raytrace::SceneSubset::All, *device_);
    ImpostorPass pass;
    pass.update(gpu, options(128, 4, false));
    EXPECT_EQ(pass.itemKind(0, 0), ImpostorPass::ItemKind::Enclosing);
    std::vector<ImpostorRay> rays;
    for (const ImpostorRay& r : sampleSpecularSurfaceRays(s, gpu, 800, 5))
        if (r.origin.y < 0.2f) rays.push_back(r);
    const auto exact = castExact(rays, gpu, rt);
    int onTop = 0;
    for (const ExactHit& e : exact) onTop += e.hit && std::abs(e.position.y) < 1e-4f;
    ASSERT_GT(onTop, 100);
    const ImpostorAccuracy a = compareHits(pass.trace(rays), exact);
    EXPECT_GT(a.hitMissAgreement, 0.97);
    EXPECT_LT(a.medianErrorMm, 0.5);
    EXPECT_LT(a.p90ErrorMm, 2.0);
    EXPECT_GT(a.originAgreement, 0.99);
}

TEST_F(ImpostorTrace, RendererRunsThePassOnlyWithSpecularObjectsAndCachesIt) {
    RendererOptions o = options(32, 2, false);
    o.vpl.count = 16;
    Renderer withSpecular(*scenes_[0], test::smallCamera(40, 30, 30.0), o);
    FrameInput in;
    in.T_world_camera = test::lookAtPose({1.5, 1.0, 1.5}, {0, 0.2, 0});
    const FrameReport& r1 = withSpecular.render(in);
    ASSERT_TRUE(r1.ran("impostor"));
    EXPECT_NE(r1.summary().find("build for 2 specular"), std::string::npos) << r1.summary();
    const FrameReport& r2 = withSpecular.render(in);
    EXPECT_NE(r2.summary().find("cached"), std::string::npos) << r2.summary();

    Scene plain;
    test::addFloor(plain, "floor", 0.0f, 2.0f, test::addMaterial(plain, glm::vec3(0.5f)),
                   Origin::Real);
    Renderer without(plain, test::smallCamera(40, 30, 30.0), o);
    EXPECT_FALSE(without.render(in).ran("impostor"));
}

}  // namespace
}  // namespace mirage::render
