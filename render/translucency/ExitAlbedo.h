#pragma once
// The share of the light scattered inside a translucent object that leaves it again, measured by
// random walks through the object's voxels (docs/translucency.md "The normalisation"). The voxel
// number map's kernel spreads all escaping light at once, so it needs this one number per
// channel; Hapke's albedo of a thick isotropic half-space (effectiveAlbedo) stands in for it
// without walks, and is low for a finite object whose light escapes through its other faces
// before the medium absorbs it.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace mirage::translucency {

// The voxelised object, in voxel units (cell c spans [c, c + 1) on each axis).
struct WalkGrid {
    glm::ivec3 dims{0};
    const std::vector<uint8_t>* inside = nullptr;    // 1: the voxel holds the medium
    const std::vector<uint8_t>* exterior = nullptr;  // 1: empty and reached from the border
    const std::vector<float>* sigma = nullptr;       // extinction per voxel edge, per voxel
};

// Where walks start: the outer surface voxels' cells, their outward normals and areas.
struct WalkStart {
    glm::ivec3 cell{0};
    glm::vec3 normal{0.0f};
    float area = 0.0f;
};

// Random walks (isotropic phase function, delta tracking through the voxels' extinction, the
// boundary as in the reference renderer: Fresnel reflection at index `ior` without bending;
// cavities crossed straight) from the start voxels, entering cosine-distributed. Returns, per
// channel, the light leaving the outer surface over the light that scattered at least once
// (albedo^n for a walk of n scatterings); Hapke's effectiveAlbedo when no walk scattered.
// Deterministic for a given seed.
glm::vec3 measureExitAlbedo(const WalkGrid& grid, const std::vector<WalkStart>& starts,
                            const glm::vec3& albedo, float ior, int walks, uint64_t seed = 1);

}  // namespace mirage::translucency
