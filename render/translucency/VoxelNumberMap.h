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
//   R_d(i, out) = c_i e^{-k tau(i, out)},   c_i = (1 - T_i) / W_i,
//   W_i = sum_j A_j e^{-k tau(i, j)},   T_i = (1/A) sum_j A_j e^{-tau(i, j)},
// per channel, with A_i the surface area a voxel stands for, A the object's outer area and k the
// kernel's falloff (kernelFalloff: 1 for the seed's e^{-tau}); the sums over j run
// over the outer surface only (light leaves the object there; what reaches a cavity wall crosses
// the cavity, whose optical thickness the LUT already leaves out). The seed's R_d = e^{-tau}
// leaves its scale open; c_i fixes it so that what enters at i and scatters leaves the surface
// in total (sum_out A_out R_d(i, out) = 1 - T_i, the share not passing straight through, which
// vanishes for an optically thin object and tends to 1 for a thick one); a_eff =
// effectiveAlbedo(albedo). Units: world metres, sigma_t in 1/m, E in W/m^2, L in W/(m^2 sr).
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

// How the light that enters at one surface voxel spreads to the others (docs/translucency.md
// "Error budget"): Extinction is the seed's R_d = e^{-tau}, the light's first free path;
// Diffusion lets multiply scattered light travel farther in a medium that absorbs little,
// R_d = e^{-k tau} per channel with k = min(1, sqrt(3 (1 - albedo))) (the diffusion
// approximation's effective attenuation over the extinction, sigma_tr / sigma_t).
enum class VnmKernel { Extinction, Diffusion };
// The per-channel k of the kernel e^{-k tau} (1 for Extinction).
glm::vec3 kernelFalloff(const glm::vec3& albedo, VnmKernel kernel);

// Where a surface voxel's normal and area (the share of the surface whose light it gathers)
// come from: Occupancy, the empty voxels around it (normal) and its exposed faces (area), which
// step along a face the voxel grid cuts at an angle; Mesh, the object's triangles (sampled
// every quarter voxel, each sample to the surface voxel standing for it).
enum class VnmSurface { Occupancy, Mesh };

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
    int resolution = 32;  // voxels along the object's longest side
    VnmKernel kernel = VnmKernel::Extinction;
    int albedoWalks = 8192;  // random walks measuring exitAlbedo()
    VnmSurface surface = VnmSurface::Occupancy;
    size_t maxLutBytes = size_t(2) << 30;  // refuse larger LUTs (2 GiB)
    std::filesystem::path cacheDir;        // empty: no disk cache
    int threads = 0;                       // 0 = hardware concurrency
};

struct SurfaceVoxel {
    glm::ivec3 cell{0};
    glm::vec3 position{0.0f};     // world, the voxel centre
    glm::vec3 normal{0.0f};       // world, unit, outward (from the occupancy around the voxel)
    float area = 0.0f;            // m^2 of the object's surface this voxel stands for
    glm::vec3 kernelScale{0.0f};  // c_i per channel (1/m^2)
    // g_o: the factor of the near field (the voxels within kNearField voxel edges) in the
    // radiance leaving this voxel, the object's mean near-field density over this voxel's
    // (VoxelNumberMap::kernelScales): the sum over voxels on a face the grid cuts at an angle
    // then does not rise and fall with the staircase.
    float nearScale = 1.0f;
    int32_t exterior = 0;  // 1: on the outer surface; 0: the wall of a cavity
};

// A surface voxel standing for a point, and its weight in the point's radiance.
struct VoxelWeight {
    int voxel = -1;
    float weight = 0.0f;
};

class VoxelNumberMap {
public:
    // Precomputes (or reads from settings.cacheDir, keyed by the object's triangles, medium and
    // the resolution). Throws mirage::Error when the LUT would exceed settings.maxLutBytes (before
    // allocating it), naming the size and what to do, and for an object without inside voxels.
    static VoxelNumberMap build(const TranslucentObject& object, const VnmSettings& settings);
    // Bytes of the LUT for S surface voxels.
    static size_t lutBytes(size_t surfaceVoxels) { return surfaceVoxels * surfaceVoxels * 2; }
    // The cache key of an object under these settings (hex).
    static std::string cacheKey(const TranslucentObject& object, const VnmSettings& settings);

    glm::ivec3 dims() const { return dims_; }
    float voxelSize() const { return voxelSize_; }
    const std::vector<SurfaceVoxel>& surface() const { return surface_; }
    float tau(int i, int j) const;
    // The surface voxel standing for a world point on (or near) the object's surface: the
    // number stored in its voxel, else the nearest numbered voxel within 2 voxels; -1 if none.
    int surfaceVoxelAt(const glm::vec3& pWorld) const;
    // The surface voxels whose radiance a world point on the surface takes, with weights summing
    // to 1: the smooth reconstruction (filterWeight of every surface voxel centre within
    // kFilterRadius voxels), else the nearest (surfaceVoxelAt) alone; empty if none. So a face
    // the grid cuts at an angle shades smoothly instead of in the voxels' stripes.
    std::vector<VoxelWeight> reconstructionAt(const glm::vec3& pWorld) const;
    // Filter radius in voxel edges, and the weight of a voxel centre at distance d (voxel
    // edges): (1 - (d / r)^2)^2 inside r, 0 beyond (translucency.glsl has the same).
    static constexpr float kFilterRadius = 1.5f;
    // The near field of a surface voxel (voxel edges between centres), normalised by nearScale.
    static constexpr float kNearField = 2.01f;
    static float filterWeight(float dVoxels);
    double precomputeSeconds() const { return seconds_; }
    bool fromCache() const { return fromCache_; }
    size_t lutBytes() const { return tau_.size() * 2; }
    float surfaceArea() const { return area_; }     // outer surface, m^2
    glm::vec3 falloff() const { return falloff_; }  // k of the kernel e^{-k tau}, per channel
    // The share of the scattered light that leaves the object, per channel, measured by random
    // walks through its voxels (ExitAlbedo.h): the kernel's total in place of effectiveAlbedo.
    glm::vec3 exitAlbedo() const { return exitAlbedo_; }
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
    void meshSurface(const TranslucentObject& o);
    void opticalThickness(const std::vector<float>& sigma, int threads);
    void kernelScales(const glm::vec3& falloff, int threads);
    bool readCache(const std::filesystem::path& file);
    void writeCache(const std::filesystem::path& file) const;

    glm::ivec3 dims_{0};
    glm::vec3 origin_{0.0f};  // world corner of voxel (0,0,0)
    float voxelSize_ = 0.0f;
    float area_ = 0.0f;
    glm::vec3 falloff_{1.0f};
    glm::vec3 exitAlbedo_{0.0f};
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
    // envSamples: cosine-distributed environment directions per surface voxel. measuredAlbedo:
    // the kernel's total is the map's exitAlbedo() (over F_t averaged over the hemisphere, which
    // the exit's F_t takes back); false: Hapke's effectiveAlbedo, the exit F_t on top.
    VnmShading(const VoxelNumberMap& map, const TranslucentObject& object,
               const raytrace::RayTracingScene& scene, int envSamples = 64,
               bool measuredAlbedo = false);
    const std::vector<glm::vec3>& irradiance() const { return E_; }
    // Radiance leaving the object at world point p towards the camera direction wOut (unit,
    // from p towards the eye): scattered light (the formula above) only. smooth: the radiance
    // of the surface voxels around p (VoxelNumberMap::reconstructionAt); else the nearest's.
    glm::vec3 scattered(const glm::vec3& p, const glm::vec3& wOut, bool smooth = true) const;
    // The radiance leaving surface voxel o before the exit boundary (no F_t).
    glm::vec3 voxelRadiance(int o) const;

    // The factor of sum_i E_i A_i R_d(i, o) in the radiance leaving voxel o before the exit F_t:
    // exitAlbedo / (pi F_t over the hemisphere), or effectiveAlbedo / pi (measured = false).
    static glm::vec3 radianceScale(const VoxelNumberMap& map, const raytrace::Medium& medium,
                                   bool measured);

private:
    const VoxelNumberMap& map_;
    raytrace::Medium medium_;
    glm::vec3 scale_;           // radianceScale
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
