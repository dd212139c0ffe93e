#pragma once
// A 3D density grid: the spatially varying part of a translucent material's extinction,
// sigma_t(x) = extinction * density(x) (docs/scene.md, MIRAGE_materials_scattering). glTF has no
// standard for volumes, so the grid is a file beside the glTF: NRRD (a text header + raw samples)
// or headerless raw samples whose size and type the glTF names.
//
// Layout and lookup: nx * ny * nz samples, x fastest, then y, then z. The samples sit at the
// centres of the nx * ny * nz cells that divide the box [boundsMin, boundsMax] (mesh-local
// units); density(p) interpolates them trilinearly, clamping to the outermost centres inside the
// box, and is 0 outside the box (so a grid smaller than the mesh leaves the rest empty).
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace mirage {

struct DensityGrid {
    int nx = 0, ny = 0, nz = 0;
    std::vector<float> values;                   // >= 0 and finite, x fastest
    glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};  // mesh-local units
    float maxValue = 0.0f;                       // largest sample (a majorant of density())

    float at(int x, int y, int z) const {
        return values[(size_t(z) * size_t(ny) + size_t(y)) * size_t(nx) + size_t(x)];
    }
    // Trilinear density at a mesh-local point; 0 outside [boundsMin, boundsMax].
    float density(const glm::vec3& pLocal) const;
};

// Limits: each dimension 1..kMaxDensityDim, at most kMaxDensitySamples samples in all.
inline constexpr int kMaxDensityDim = 1024;
inline constexpr size_t kMaxDensitySamples = size_t(256) * 256 * 256;

enum class DensitySampleType { Uint8, Uint16, Float32, Float64 };

// Parses an NRRD file (header "NRRD000N", fields type, dimension: 3, sizes, encoding: raw,
// endian; integer types are normalised to [0, 1]). Throws mirage::Error naming the field and
// what to do; the caller prefixes the file name. Bounds are left for the caller to set.
DensityGrid parseNrrdDensity(const std::string& bytes);
// Parses headerless little-endian samples of the given dimensions and type.
DensityGrid parseRawDensity(const std::string& bytes, int nx, int ny, int nz,
                            DensitySampleType type);
// "uint8", "uint16", "float32", "float64"; throws mirage::Error for anything else.
DensitySampleType densitySampleType(const std::string& name);

}  // namespace mirage
