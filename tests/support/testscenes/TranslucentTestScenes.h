#pragma once
// Translucent objects for the reference renderer's media tests and the voxel number map's
// accuracy tests: a homogeneous cube, a cube with a spherical cavity (the voxel number map
// paper's own example), a cube whose density is a gradient, each with a camera and lights.
#include <memory>

#include "testscenes/RaytraceTestScenes.h"

namespace mirage::raytrace::test {

// A translucent material: extinction (1/m at density 1), single-scattering albedo, boundary IOR.
inline Material translucentMaterial(float extinction, glm::vec3 albedo, float ior = 1.0f,
                                    std::shared_ptr<const DensityGrid> density = nullptr) {
    Material m;
    m.name = "translucent";
    m.metallic = 0.0f;
    m.roughness = 1.0f;
    m.ior = ior;
    m.scattering.present = true;
    m.scattering.extinction = extinction;
    m.scattering.albedo = albedo;
    m.scattering.density = std::move(density);
    return m;
}

// A grid of nx x ny x nz samples over [lo, hi] from a function of the sample centre.
template <typename Fn>
std::shared_ptr<const DensityGrid> makeDensityGrid(int nx, int ny, int nz, glm::vec3 lo,
                                                   glm::vec3 hi, Fn&& fn) {
    auto g = std::make_shared<DensityGrid>();
    g->nx = nx;
    g->ny = ny;
    g->nz = nz;
    g->boundsMin = lo;
    g->boundsMax = hi;
    g->values.resize(size_t(nx) * size_t(ny) * size_t(nz));
    for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x) {
                glm::vec3 c = lo + (glm::vec3(x, y, z) + 0.5f) / glm::vec3(nx, ny, nz) * (hi - lo);
                float v = fn(c);
                g->values[(size_t(z) * size_t(ny) + size_t(y)) * size_t(nx) + size_t(x)] = v;
                g->maxValue = std::max(g->maxValue, v);
            }
    return g;
}

// A sphere whose normals and winding face its centre: the wall of a cavity inside a medium.
inline Primitive cavityPrimitive(glm::vec3 centre, float radius, int rings = 24,
                                 int segments = 32) {
    Primitive p = mirage::test::uvSpherePrimitive(centre, radius, rings, segments);
    for (auto& n : p.normals) n = -n;
    for (size_t i = 0; i < p.indices.size(); i += 3) std::swap(p.indices[i + 1], p.indices[i + 2]);
    return p;
}

enum class TranslucentShape { Cube, CubeWithCavity, GradientCube, EmptyCore };

struct TranslucentSceneOptions {
    TranslucentShape shape = TranslucentShape::Cube;
    float extinction = 8.0f;  // 1/m: tau 4 across the 0.5 m cube
    glm::vec3 albedo{0.9f, 0.8f, 0.6f};
    float ior = 1.3f;
    float cavityRadius = 0.17f;  // m, centred
    // Behind the cube as the tests' camera sees it: the back-lit glow, where a cavity shows.
    glm::vec3 lightPosition{-0.55f, -0.3f, -0.85f};
    float lightIntensity = 3.0f;  // W/sr
    float environment = 0.03f;    // uniform environment radiance
    bool cavityInScene = true;    // false: the cube without its cavity (the "cavity ignored" case)
    Origin objectOrigin = Origin::Virtual;  // the cube
    Origin lightOrigin = Origin::Real;
    // The cube turned about +Y (degrees): its faces then cut the world-aligned voxel grid of the
    // voxel number map at an angle, as the sample scene's jade cube does.
    float yawDegrees = 0.0f;
};

// A translucent cube [-0.25, 0.25]^3 (one mesh: the box, and for the cavity variant the inward
// sphere wall, both with the same material), a point light behind it and a dim uniform
// environment written under `dir`. The gradient cube's density rises along x from 0.2 to 1.8
// (an 8^3 grid); the empty-core cube's 16^3 grid is 0 within cavityRadius of the centre (a
// cavity made by the density, not by the mesh).
inline Scene translucentTestScene(const TranslucentSceneOptions& o,
                                  const std::filesystem::path& dir) {
    Scene s;
    setEnvironment(s, dir / "env.exr", constantImage(16, 8, o.environment));
    std::shared_ptr<const DensityGrid> grid;
    if (o.shape == TranslucentShape::GradientCube)
        grid = makeDensityGrid(8, 8, 8, glm::vec3(-0.25f), glm::vec3(0.25f),
                               [](glm::vec3 p) { return 0.2f + 1.6f * (p.x + 0.25f) / 0.5f; });
    if (o.shape == TranslucentShape::EmptyCore)  // density 0 within the cavity's radius
        grid = makeDensityGrid(16, 16, 16, glm::vec3(-0.25f), glm::vec3(0.25f), [&](glm::vec3 p) {
            return glm::length(p) < o.cavityRadius ? 0.0f : 1.0f;
        });
    s.materials.push_back(translucentMaterial(o.extinction, o.albedo, o.ior, grid));
    Mesh mesh;
    mesh.name = "translucent";
    Primitive box = boxPrimitive(glm::vec3(-0.25f), glm::vec3(0.25f));
    box.material = 0;
    mesh.primitives.push_back(std::move(box));
    if (o.shape == TranslucentShape::CubeWithCavity && o.cavityInScene) {
        Primitive cavity = cavityPrimitive(glm::vec3(0.0f), o.cavityRadius);
        cavity.material = 0;
        mesh.primitives.push_back(std::move(cavity));
    }
    s.meshes.push_back(std::move(mesh));
    Node n;
    n.name = "translucent";
    n.mesh = 0;
    const glm::dmat4 turn =
        glm::rotate(glm::dmat4(1.0), glm::radians(double(o.yawDegrees)), glm::dvec3(0, 1, 0));
    mirage::test::addRootNode(s, std::move(n), turn, o.objectOrigin);
    Light l;
    l.type = Light::Type::Point;
    l.intensity = o.lightIntensity;
    addLight(s, "light", l, translate(glm::dvec3(o.lightPosition)), o.lightOrigin);
    return s;
}

}  // namespace mirage::raytrace::test
