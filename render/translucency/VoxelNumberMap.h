#pragma once
// The voxel number map (Mochida et al., "Real-time rendering of heterogeneous translucent objects
// using voxel number map"): the precomputation part and the run-time formula, for one translucent
// object (docs/translucency.md).
//
// Precomputation: the object is voxelised (cubic voxels, `resolution` along its longest side),
// the voxels on its surface (inside voxels with an outside 6-neighbour: the outer surface and the
// walls of cavities) are numbered 0..S-1, and the optical thickness
// tau(i, j) = integral of sigma_t along the segment between surface voxels i and j (through
// inside voxels only: a cavity or the air outside a concave part adds nothing) fills an S x S
// look-up table. Run time: irradiance E(x_in) = F_t |N.w| I at every surface voxel, then
//   L(x_out, w_out) = (1/pi) F_t(w_out) a_eff sum_i E_i A_i R_d(i, out),
//   R_d(i, out) = c_i e^{-tau(i, out)},   c_i = 1/W_i - 1/A,   W_i = sum_j A_j e^{-tau(i, j)},
// with A_i the surface area a voxel stands for and A the object's outer area; the sums over j run
// over the outer surface only (light leaves the object there; what reaches a cavity wall crosses
// the cavity, whose optical thickness the LUT already leaves out). The seed's R_d = e^{-tau}
// leaves its scale open; c_i fixes it so that what enters at i and scatters leaves the surface
// in total (sum_out A_out R_d(i, out) = 1 - mean_j e^{-tau(i, j)}, which vanishes for an optically
// thin object and tends to 1 for a thick one); a_eff = effectiveAlbedo(albedo). Units: world
// metres, sigma_t in 1/m, E in W/m^2, L in W/(m^2 sr).
//
// The LUT grows with S^2 (2 bytes per entry, IEEE half floats): ~6 S^2 / 1e6 MB for a cube,
// S ~ 6 n^2 at resolution n. `build` refuses before allocating a LUT above `maxLutBytes`.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"
#include "core/scene/Scene.h"
#include "render/raytrace/RayTracingScene.h"

namespace mirage::translucency {

// One translucent object: the world-space triangles of one mesh instance's primitives that share
// a translucent material, and its medium.
struct TranslucentObject {
    std::string name;                  // node name (messages)
    std::vector<glm::vec3> positions;  // world, metres
    std::vector<uint32_t> indices;     // triangle list
    raytrace::Medium medium;
};

// The fraction of the light entering a thick medium of single-scattering albedo `albedo` that
// leaves it again after any number of scatterings: Hapke's bihemispherical reflectance of an
// isotropic half-space, (1 - g) / (1 + g), g = sqrt(1 - albedo). The kernel spreads all escaping
// light over the surface at once, so it takes this albedo rather than the single-scattering one
// (1 stays 1: a white medium loses nothing).
glm::vec3 effectiveAlbedo(const glm::vec3& albedo);

// The scale k of the optical thickness in the transmittance a translucent object's shadow lets
// through, T = F_t,in F_t,out e^{-k tau} per channel (docs/translucency.md "Shadows").
glm::vec3 shadowExtinctionScale(const glm::vec3& albedo);

// F_t: the fraction of light crossing the smooth boundary of a medium of index `ior` at
// |cos| = cosAbs to the normal (1 - Fresnel reflectance; 1 for ior 1).
float boundaryTransmittance(float ior, float cosAbs);
// F_t averaged over a cosine-weighted hemisphere, 2 int_0^1 F_t(mu) mu dmu: the share of a
// uniform environment's irradiance that enters the medium.
float hemisphericalTransmittance(float ior);

// The scene's translucent objects (one per mesh instance and translucent material).
std::vector<TranslucentObject> translucentObjects(const Scene& scene);

struct VnmSettings {
    int resolution = 32;                   // voxels along the object's longest side
    size_t maxLutBytes = size_t(2) << 30;  // refuse larger LUTs (2 GiB)
    std::filesystem::path cacheDir;        // empty: no disk cache
    int threads = 0;                       // 0 = hardware concurrency
};

struct SurfaceVoxel {
    glm::ivec3 cell{0};
    glm::vec3 position{0.0f};  // world, the voxel centre
    glm::vec3 normal{0.0f};    // world, unit, outward (from the occupancy around the voxel)
    float area = 0.0f;         // m^2 of the object's surface this voxel stands for
    float kernelScale = 0.0f;  // c_i (1/m^2)
    int32_t exterior = 0;      // 1: on the outer surface; 0: the wall of a cavity
};

class VoxelNumberMap {
public:
    // Precomputes (or reads from settings.cacheDir, keyed by the object's triangles, medium and
    // the resolution). Throws mirage::Error when the LUT would exceed settings.maxLutBytes (before
    // allocating it), naming the size and what to do, and for an object without inside voxels.
    static VoxelNumberMap build(const TranslucentObject& object, const VnmSettings& settings);
    // Bytes of the LUT for S surface voxels.
    static size_t lutBytes(size_t surfaceVoxels) { return surfaceVoxels * surfaceVoxels * 2; }
    // The cache key of an object at a resolution (hex).
    static std::string cacheKey(const TranslucentObject& object, int resolution);

    glm::ivec3 dims() const { return dims_; }
    float voxelSize() const { return voxelSize_; }
    const std::vector<SurfaceVoxel>& surface() const { return surface_; }
    float tau(int i, int j) const;
    // The surface voxel standing for a world point on (or near) the object's surface: the
    // number stored in its voxel, else the nearest numbered voxel within 2 voxels; -1 if none.
    int surfaceVoxelAt(const glm::vec3& pWorld) const;
    double precomputeSeconds() const { return seconds_; }
    bool fromCache() const { return fromCache_; }
    size_t lutBytes() const { return tau_.size() * 2; }
    float surfaceArea() const { return area_; }  // outer surface, m^2
    // For uploading to the GPU: the world corner of voxel (0,0,0), the voxel number per cell
    // (x fastest, then y, then z; -1 = no surface voxel) and the S x S LUT of tau (IEEE half
    // floats, row i = from surface voxel i).
    glm::vec3 origin() const { return origin_; }
    const std::vector<int32_t>& numbers() const { return number_; }
    const std::vector<uint16_t>& tauHalf() const { return tau_; }

private:
    int cellIndex(glm::ivec3 c) const { return (c.z * dims_.y + c.y) * dims_.x + c.x; }
    // The steps of build().
    std::vector<uint8_t> voxelise(const TranslucentObject& o, int resolution);
    std::vector<float> extinction(const TranslucentObject& o,
                                  const std::vector<uint8_t>& inside) const;
    std::vector<uint8_t> exteriorOf(const std::vector<uint8_t>& inside) const;
    void findSurface(const TranslucentObject& o, const VnmSettings& s,
                     const std::vector<uint8_t>& inside, const std::vector<uint8_t>& exterior);
    void opticalThickness(const std::vector<float>& sigma, int threads);
    bool readCache(const std::filesystem::path& file);
    void writeCache(const std::filesystem::path& file) const;

    glm::ivec3 dims_{0};
    glm::vec3 origin_{0.0f};  // world corner of voxel (0,0,0)
    float voxelSize_ = 0.0f;
    float area_ = 0.0f;
    std::vector<int32_t> number_;  // per voxel: surface number or -1 (the voxel number map)
    std::vector<SurfaceVoxel> surface_;
    std::vector<uint16_t> tau_;  // S x S, half floats
    double seconds_ = 0.0;
    bool fromCache_ = false;
};

// The run-time formula on the CPU, the definition the GPU passes follow: irradiance at the
// surface voxels from the scene's punctual lights and environment (visibility by ray casting
// against the scene, standing in for shadow maps), and radiance leaving a surface point.
class VnmShading {
public:
    // envSamples: cosine-distributed environment directions per surface voxel.
    VnmShading(const VoxelNumberMap& map, const TranslucentObject& object,
               const raytrace::RayTracingScene& scene, int envSamples = 64);
    const std::vector<glm::vec3>& irradiance() const { return E_; }
    // Radiance leaving the object at world point p towards the camera direction wOut (unit,
    // from p towards the eye): scattered light (the formula above) only.
    glm::vec3 scattered(const glm::vec3& p, const glm::vec3& wOut) const;

private:
    const VoxelNumberMap& map_;
    raytrace::Medium medium_;
    std::vector<glm::vec3> E_;  // per surface voxel, W/m^2 (after F_t at entry)
};

// A whole image of the object by the voxel number map on the CPU: per pixel the camera ray's
// first hit; on a translucent object: its scattered light, plus the Fresnel-reflected
// environment and the background seen straight through (F_t at both crossings, e^{-tau} of the
// chord from the LUT); elsewhere 0. `mask` (CV_8U) marks pixels whose first hit is the object.
struct VnmImage {
    cv::Mat radiance;  // CV_32FC3 linear
    cv::Mat mask;
};
VnmImage renderVnm(const VoxelNumberMap& map, const TranslucentObject& object,
                   const raytrace::RayTracingScene& scene, const CameraIntrinsics& intrinsics,
                   const Pose& T_world_camera, int envSamples = 64);

}  // namespace mirage::translucency
