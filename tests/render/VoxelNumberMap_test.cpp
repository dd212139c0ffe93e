// The voxel number map (render/translucency/VoxelNumberMap.h): the precomputation's numbers
// (surface voxels, optical thickness through a medium and a cavity, the LUT limit, the disk
// cache), and the whole method against the reference renderer over the object: a homogeneous
// cube, a cube with a spherical cavity and a density gradient, each with a must-fail (the cavity
// ignored, sigma_t doubled).
#include <gtest/gtest.h>

#include <fstream>

#include <opencv2/imgproc.hpp>
#include "core/Error.h"
#include "core/image/ImageCompare.h"
#include "core/image/ImageIO.h"
#include "render/raytrace/ReferenceRenderer.h"
#include "render/translucency/VoxelNumberMap.h"
#include "tests/support/TestSupport.h"
#include "testscenes/TranslucentTestScenes.h"

namespace mirage::translucency {
namespace {

using namespace mirage::raytrace::test;
namespace fs = std::filesystem;

// Indices of the surface voxels nearest two points.
int nearest(const VoxelNumberMap& m, glm::vec3 p) {
    int best = -1;
    float bestD = 1e30f;
    for (size_t i = 0; i < m.surface().size(); ++i) {
        float d = glm::length(m.surface()[i].position - p);
        if (d < bestD) {
            bestD = d;
            best = int(i);
        }
    }
    return best;
}

TranslucentObject objectOf(const Scene& s) {
    auto objects = translucentObjects(s);
    EXPECT_EQ(objects.size(), 1u);
    return objects.at(0);
}

TEST(VoxelNumberMap, PrecomputationCountsSurfaceVoxelsAndOpticalThickness) {
    const fs::path dir = mirage::test::outputDir("vnm_precompute");
    TranslucentSceneOptions o;
    VnmSettings settings;
    settings.resolution = 16;
    settings.threads = 2;
    const VoxelNumberMap cube =
        VoxelNumberMap::build(objectOf(translucentTestScene(o, dir)), settings);
    // A 16^3 block of inside voxels: its shell has 16^3 - 14^3 voxels.
    EXPECT_EQ(cube.surface().size(), size_t(16 * 16 * 16 - 14 * 14 * 14));
    EXPECT_NEAR(cube.surfaceArea(), 1.5f, 1e-4f);
    const float h = 0.5f / 16.0f;
    int a = nearest(cube, {-0.25f, 0.01f, 0.01f}), b = nearest(cube, {0.25f, 0.01f, 0.01f});
    // Centre to centre, 15 voxels apart: sigma_t times that distance.
    EXPECT_NEAR(cube.tau(a, b), o.extinction * 15.0f * h, 0.02f);
    EXPECT_EQ(cube.tau(a, b), cube.tau(b, a));
    EXPECT_EQ(cube.tau(a, a), 0.0f);
    const SurfaceVoxel& side = cube.surface()[size_t(a)];
    EXPECT_NEAR(side.normal.x, -1.0f, 1e-5f);
    EXPECT_EQ(cube.surfaceVoxelAt({-0.25f, 0.01f, 0.01f}), a);

    // The cavity: its wall voxels are surface voxels too, and the path through the centre loses
    // the cavity's diameter (0.34 m) of medium.
    o.shape = TranslucentShape::CubeWithCavity;
    const VoxelNumberMap hollow =
        VoxelNumberMap::build(objectOf(translucentTestScene(o, dir)), settings);
    EXPECT_GT(hollow.surface().size(), cube.surface().size() + 200);
    a = nearest(hollow, {-0.25f, 0.01f, 0.01f});
    b = nearest(hollow, {0.25f, 0.01f, 0.01f});
    EXPECT_NEAR(hollow.tau(a, b), o.extinction * (15.0f * h - 2 * o.cavityRadius),
                2.5f * h * o.extinction);
    EXPECT_LT(hollow.tau(a, b), 0.5f * cube.tau(a, b));
}

TEST(VoxelNumberMap, LutLimitAndDiskCache) {
    const fs::path dir = mirage::test::outputDir("vnm_cache");
    fs::remove_all(dir / "cache");
    TranslucentSceneOptions o;
    const TranslucentObject object = objectOf(translucentTestScene(o, dir));
    VnmSettings settings;
    settings.resolution = 12;
    settings.threads = 2;
    settings.maxLutBytes = 1 << 20;  // 1 MiB: 12^3 - 10^3 = 728 surface voxels need 1.01 MiB
    try {
        VoxelNumberMap::build(object, settings);
        ADD_FAILURE() << "a LUT above the limit was built";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("728 surface voxels"), std::string::npos) << m;
        EXPECT_NE(m.find("lower the voxel resolution"), std::string::npos) << m;
    }
    // 128^3 under the default 2 GiB limit: refused before the 17.4 GiB LUT is allocated.
    VnmSettings fine;
    fine.resolution = 128;
    fine.threads = 2;
    try {
        VoxelNumberMap::build(object, fine);
        ADD_FAILURE() << "a 128^3 LUT was built";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("96776 surface voxels"), std::string::npos) << m;
        EXPECT_NE(m.find("17863 MiB"), std::string::npos) << m;
        EXPECT_NE(m.find("limit of 2048 MiB"), std::string::npos) << m;
    }
    settings.maxLutBytes = size_t(1) << 30;
    settings.cacheDir = dir / "cache";
    const VoxelNumberMap first = VoxelNumberMap::build(object, settings);
    EXPECT_FALSE(first.fromCache());
    EXPECT_EQ(first.lutBytes(), size_t(728) * 728 * 2);
    const VoxelNumberMap second = VoxelNumberMap::build(object, settings);
    EXPECT_TRUE(second.fromCache());
    ASSERT_EQ(second.surface().size(), first.surface().size());
    EXPECT_EQ(second.tau(3, 700), first.tau(3, 700));
    EXPECT_EQ(second.surface()[5].kernelScale.y, first.surface()[5].kernelScale.y);
    EXPECT_EQ(second.falloff().x, first.falloff().x);
    // Another density (or mesh) is another key; a damaged cache file is recomputed.
    TranslucentObject denser = object;
    denser.medium.extinction *= 2.0f;
    EXPECT_NE(VoxelNumberMap::cacheKey(denser, settings),
              VoxelNumberMap::cacheKey(object, settings));
    VnmSettings finer = settings;
    finer.resolution = 16;
    EXPECT_NE(VoxelNumberMap::cacheKey(object, finer), VoxelNumberMap::cacheKey(object, settings));
    // The kernel's falloff depends on the albedo, and the areas on the surface's source.
    TranslucentObject whiter = object;
    whiter.medium.albedo = glm::vec3(0.99f);
    EXPECT_NE(VoxelNumberMap::cacheKey(whiter, settings),
              VoxelNumberMap::cacheKey(object, settings));
    VnmSettings mesh = settings;
    mesh.surface = VnmSurface::Mesh;
    EXPECT_NE(VoxelNumberMap::cacheKey(object, mesh), VoxelNumberMap::cacheKey(object, settings));
    const fs::path file =
        settings.cacheDir / ("vnm-" + VoxelNumberMap::cacheKey(object, settings) + ".bin");
    ASSERT_TRUE(fs::exists(file));
    fs::resize_file(file, fs::file_size(file) / 2);
    const VoxelNumberMap third = VoxelNumberMap::build(object, settings);
    EXPECT_FALSE(third.fromCache());
    EXPECT_EQ(third.tau(3, 700), first.tau(3, 700));
    // A header claiming ~10^6 surface voxels (a 2 TB LUT) is rejected by the file's size, not
    // allocated. S is the 64-bit field after magic, version, dims, origin, voxel size, area, the
    // kernel's falloff and the exit albedo.
    {
        std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
        const uint64_t huge = (uint64_t(1) << 20) - 1;
        f.seekp(4 + 4 + 12 + 12 + 4 + 4 + 12 + 12);
        f.write(reinterpret_cast<const char*>(&huge), sizeof huge);
    }
    const VoxelNumberMap fourth = VoxelNumberMap::build(object, settings);
    EXPECT_FALSE(fourth.fromCache());
    EXPECT_EQ(fourth.surface().size(), first.surface().size());
}

// The exit albedo by random walks (ExitAlbedo.h): a white medium loses nothing, so every walk
// that scattered leaves (1 within the walks' noise, the boundary's reflections included); a
// black one returns nothing; a finite cube loses less than Hapke's thick half-space, and the
// thinner (sigma_t halved) the more leaves.
TEST(VoxelNumberMap, ExitAlbedoByRandomWalks) {
    const fs::path dir = mirage::test::outputDir("vnm_exit_albedo");
    TranslucentSceneOptions o;
    o.albedo = {1.0f, 0.8f, 0.0f};
    VnmSettings settings;
    settings.resolution = 12;
    settings.threads = 2;
    const VoxelNumberMap thick =
        VoxelNumberMap::build(objectOf(translucentTestScene(o, dir)), settings);
    const glm::vec3 a = thick.exitAlbedo();
    EXPECT_NEAR(a.x, 1.0f, 0.02f);
    EXPECT_EQ(a.z, 0.0f);
    const float hapke = effectiveAlbedo(o.albedo).y;
    EXPECT_GT(a.y, hapke) << "a 0.5 m cube of tau 4 keeps less than a half-space";
    EXPECT_LT(a.y, 0.8f);
    o.extinction *= 0.5f;
    const VoxelNumberMap thin =
        VoxelNumberMap::build(objectOf(translucentTestScene(o, dir)), settings);
    EXPECT_GT(thin.exitAlbedo().y, a.y);
    std::cout << "exit albedo (G, albedo 0.8): Hapke " << hapke << ", tau 4 across " << a.y
              << ", tau 2 across " << thin.exitAlbedo().y << "\n";
}

struct Accuracy {
    double psnr;
    int pixels;
};

// PSNR (peak = the reference's brightest object pixel) of the voxel number map's image of a
// scene against the reference's, over the pixels where both see the object.
Accuracy accuracy(const Scene& truthScene, const Scene& vnmScene, const std::string& name) {
    const fs::path dir = mirage::test::outputDir("vnm_images_" + name);
    auto cam = lookAtCamera(32, 32, 70.0, {0.9, 0.55, 1.3}, {0, 0, 0});
    raytrace::RayTracingScene truthRt(truthScene, raytrace::SceneSubset::All, testDevice());
    raytrace::RenderSettings st;
    st.samplesPerPixel = 48;
    st.threads = 2;
    st.seed = 5;
    const cv::Mat truth = raytrace::render(truthRt, cam, st).radiance;
    VnmSettings settings;
    settings.resolution = 16;
    settings.threads = 2;
    const TranslucentObject object = objectOf(vnmScene);
    const VoxelNumberMap map = VoxelNumberMap::build(object, settings);
    raytrace::RayTracingScene vnmRt(vnmScene, raytrace::SceneSubset::All, testDevice());
    const VnmImage img = renderVnm(map, object, vnmRt, cam.intrinsics, cam.T_world_camera);
    EXPECT_TRUE(cv::checkRange(img.radiance, true, nullptr, 0.0, 1e6)) << name;
    double peak;
    cv::minMaxLoc(truth.reshape(1), nullptr, &peak);
    writeLinearRgb(dir / (name + "_reference.exr"), truth);
    writeLinearRgb(dir / (name + "_vnm.exr"), img.radiance);
    cv::Mat both;
    cv::hconcat(truth, img.radiance, both);
    cv::resize(both, both, {}, 8, 8, cv::INTER_NEAREST);
    writeLinearRgb(dir / (name + "_side.png"), both, float(1.0 / peak));
    return {psnr(img.radiance, truth, peak, img.mask), cv::countNonZero(img.mask)};
}

// The voxel number map against the reference (multiple scattering, 48 spp) over the pixels where
// the object is seen, back-lit (32 x 32 pixels, 16^3 voxels). Floors sit ~1 dB under what was
// measured (2026-12-02: cube 17.55 dB, cavity 18.54 dB, gradient 14.80 dB); each must-fail was
// measured below its floor (sigma_t doubled: 13.73 / 15.51 / 13.13 dB; the cavity ignored:
// 14.53 dB). The figures are deterministic (fixed seeds, independent of the thread count).
struct AccuracyCase {
    TranslucentShape shape;
    double floorDb;
};

void expectAccuracy(const AccuracyCase& c, const std::string& name) {
    const fs::path dir = mirage::test::outputDir("vnm_" + name);
    TranslucentSceneOptions o;
    o.shape = c.shape;
    const Scene truth = translucentTestScene(o, dir);
    const Accuracy a = accuracy(truth, truth, name);
    EXPECT_GT(a.pixels, 500);
    EXPECT_GT(a.psnr, c.floorDb) << name;
    TranslucentSceneOptions doubled = o;
    doubled.extinction *= 2.0f;
    EXPECT_LT(accuracy(truth, translucentTestScene(doubled, dir), name + "_doubled").psnr,
              c.floorDb)
        << name << " with sigma_t doubled";
    if (c.shape == TranslucentShape::CubeWithCavity) {
        TranslucentSceneOptions ignored = o;
        ignored.cavityInScene = false;
        EXPECT_LT(accuracy(truth, translucentTestScene(ignored, dir), name + "_no_cavity").psnr,
                  c.floorDb)
            << name << " with the cavity ignored";
    }
}

TEST(VoxelNumberMap, HomogeneousCubeAgreesWithTheReference) {
    expectAccuracy({TranslucentShape::Cube, 16.5}, "cube");
}

TEST(VoxelNumberMap, CubeWithSphericalCavityAgreesWithTheReference) {
    expectAccuracy({TranslucentShape::CubeWithCavity, 17.5}, "cavity");
}

TEST(VoxelNumberMap, DensityGradientAgreesWithTheReference) {
    expectAccuracy({TranslucentShape::GradientCube, 14.0}, "gradient");
}

// Hard cases, floors ~1 dB under the measured figures (2026-12-02): optically thin (tau 0.25
// across, near-transparent: 15.65 dB; the reference's forward-scattered glow around the light
// behind is what the isotropic kernel cannot show), optically thick (tau 30: 23.10 dB), a density
// grid with an empty core (20.02 dB; the core ignored, i.e. a homogeneous grid: 16.27 dB, asserted
// below the floor), and lit from the front instead of the back (21.14 dB).
TEST(VoxelNumberMap, HardCases) {
    struct Case {
        const char* name;
        TranslucentShape shape;
        float extinction;
        bool frontLit;
        double floorDb;
    };
    for (const Case& c : {Case{"thin", TranslucentShape::Cube, 0.5f, false, 14.5},
                          Case{"thick", TranslucentShape::Cube, 60.0f, false, 22.0},
                          Case{"empty_core", TranslucentShape::EmptyCore, 8.0f, false, 19.0},
                          Case{"front_lit", TranslucentShape::Cube, 8.0f, true, 20.0}}) {
        SCOPED_TRACE(c.name);
        const fs::path dir = mirage::test::outputDir(std::string("vnm_hard_") + c.name);
        TranslucentSceneOptions o;
        o.shape = c.shape;
        o.extinction = c.extinction;
        if (c.frontLit) o.lightPosition = {0.9f, 0.7f, 0.6f};
        const Scene truth = translucentTestScene(o, dir);
        const Accuracy a = accuracy(truth, truth, c.name);
        EXPECT_GT(a.pixels, 500);
        EXPECT_GT(a.psnr, c.floorDb);
        if (c.shape == TranslucentShape::EmptyCore) {
            TranslucentSceneOptions filled = o;
            filled.shape = TranslucentShape::Cube;
            EXPECT_LT(accuracy(truth, translucentTestScene(filled, dir), "core_ignored").psnr,
                      c.floorDb);
        }
    }
}

// The bundled sample scene's translucent jade cube: one object (box + cavity wall), its density
// grid read from the NRRD beside the glTF, and a map whose cavity walls are not on the outside.
TEST(VoxelNumberMap, TabletopTranslucentSampleScene) {
    const Scene scene =
        loadScene(mirage::test::dataDir() / "scenes" / "tabletop" / "tabletop_translucent.gltf");
    const auto objects = translucentObjects(scene);
    ASSERT_EQ(objects.size(), 1u);
    const TranslucentObject& jade = objects[0];
    EXPECT_EQ(jade.name, "jade_cube");
    ASSERT_TRUE(jade.medium.density);
    EXPECT_EQ(jade.medium.density->nx, 8);
    EXPECT_NEAR(jade.medium.majorant, 120.0f * (0.4f + 1.2f * 7.5f / 8.0f), 1e-3f);
    VnmSettings settings;
    settings.resolution = 12;
    settings.threads = 2;
    const VoxelNumberMap map = VoxelNumberMap::build(jade, settings);
    int outer = 0, walls = 0;
    for (const SurfaceVoxel& v : map.surface()) (v.exterior ? outer : walls)++;
    // The cube is turned 15 degrees about +Y in a world-aligned grid: a shell of a few hundred
    // voxels outside, the cavity's wall (r = 16 mm of a 60 mm cube) inside.
    EXPECT_GT(outer, 300);
    EXPECT_GT(walls, 20);
    EXPECT_LT(walls, outer / 4);
}

}  // namespace
}  // namespace mirage::translucency
