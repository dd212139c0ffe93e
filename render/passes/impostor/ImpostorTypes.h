#pragma once
// Host mirrors of the std430 structs of render/passes/impostor/trace.glsl. Layout is checked with
// static_asserts; a change on one side must be made on the other.
#include <glm/glm.hpp>

namespace mirage::render {

// One impostor of a surrounding draw item for one specular object (std430, binding
// kBindingImpostorRecords). Its box is centre + [-1,1] * halfExtent along the three axes (world,
// metres); axisW points away from the specular object (billboards) or is the plane normal
// (planar items, halfExtent w = 0).
struct GpuImpostor {
    glm::vec4 centre;  // xyz world centre of the box; w unused
    glm::vec4 axisU;   // xyz unit; w = half extent along u (m)
    glm::vec4 axisV;   // xyz unit; w = half extent along v (m)
    glm::vec4 axisW;   // xyz unit; w = half extent along w (m), 0 for planar items
    glm::ivec4 info;  // x = layer in the impostor arrays, y = kind (0 billboard, 1 plane), z = draw
};
static_assert(sizeof(GpuImpostor) == 80);

// Per specular object (std430, binding kBindingImpostorObjects, after a GpuImpostorHeader).
struct GpuImpostorObject {
    glm::vec4 centre;  // xyz bounding-sphere centre (world, m) = cube-map centre; w = radius
    glm::ivec4 range;  // x = first impostor, y = impostor count, z = first layer of its baseline
                       // cube map (6 faces), w = first layer of its enclosing-items cube, -1 = none
    glm::vec4 params;  // x = enclosing search distance (m)
};
static_assert(sizeof(GpuImpostorObject) == 48);

struct GpuImpostorHeader {
    glm::ivec4 mode;   // x = 1: plain cube-map baseline, y = refinement steps, z = object count,
                       // w = coarse linear-search samples per impostor
    glm::vec4 params;  // x = cube-map resolution, y = impostor resolution
};
static_assert(sizeof(GpuImpostorHeader) == 32);

}  // namespace mirage::render
