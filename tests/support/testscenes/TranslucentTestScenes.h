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

}  // namespace mirage::raytrace::test
