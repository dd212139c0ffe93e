#pragma once
// Accuracy of traceSurroundings() against exact Embree ray casts (render/raytrace): rays leave
// the specular objects' surfaces in random directions of the outer hemisphere; each is traced with
// the impostors (or the cube-map baseline) on the GPU and cast exactly with Embree, ignoring the
// specular object the ray leaves (its own geometry is not in its impostors). World = glTF frame
// (metres). Used by the tests and by the impostor benchmark.
#include <cstdint>
#include <vector>

#include "core/scene/Scene.h"
#include "render/GpuScene.h"
#include "render/passes/impostor/ImpostorPass.h"
#include "render/raytrace/RayTracingScene.h"

namespace mirage::render {

// The exact answer for one ray.
struct ExactHit {
    bool hit = false;
    glm::vec3 position{0.0f};  // world (m)
    int origin = kOriginNone;
    int draw = -1;  // GpuScene draw index of the surface hit
};

struct ImpostorAccuracy {
    int rays = 0;
    int bothHit = 0, bothMiss = 0;
    int falseHit = 0;               // traced a hit where the exact ray leaves the scene
    int falseMiss = 0;              // traced a miss where the exact ray hits something
    double hitMissAgreement = 0.0;  // (bothHit + bothMiss) / rays
    double originAgreement = 0.0;   // over bothHit: same REAL/VIRTUAL origin
    double medianErrorMm = 0.0, p90ErrorMm = 0.0, meanErrorMm = 0.0;  // over bothHit
    std::vector<double> errorsMm;                                     // per ray, -1 unless bothHit
};

// `count` rays per specular object from area-uniform points of its surface (offset 0.1 mm along
// the outward normal), directions uniform over the hemisphere around the normal. `scene` must be
// the one `gpu` was built from (draw order is checked). Deterministic for a seed.
std::vector<ImpostorRay> sampleSpecularSurfaceRays(const Scene& scene, const GpuScene& gpu,
                                                   int count, uint32_t seed);

// Exact closest hits (Embree, all geometry) skipping the draw each ray leaves. `exact` must be
// built from the same scene with SceneSubset::All (its geometry ids = GpuScene draw indices).
std::vector<ExactHit> castExact(const std::vector<ImpostorRay>& rays, const GpuScene& gpu,
                                const raytrace::RayTracingScene& exact);

ImpostorAccuracy compareHits(const std::vector<ImpostorHit>& traced,
                             const std::vector<ExactHit>& exact);

}  // namespace mirage::render
