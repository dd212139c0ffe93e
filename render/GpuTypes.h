#pragma once
// Host mirrors of the GPU structs in render/common.glsl (std140 uniform blocks, std430 storage
// buffers). Layout is checked with static_asserts; a change on one side must be made on the other.
#include <cstdint>

#include <glm/glm.hpp>

namespace mirage::render {

inline constexpr int kMaxLights = 8;
inline constexpr int kLightPoint = 0, kLightSpot = 1, kLightDirectional = 2;
inline constexpr int kOriginNone = 0, kOriginReal = 1, kOriginVirtual = 2;

// Uniform/storage binding points shared by every pass (named, never magic numbers in passes).
inline constexpr unsigned kBindingFrame = 0, kBindingLights = 1, kBindingVpls = 2,
                          kBindingMaterials = 3, kBindingIsmPoints = 4;

// Reflected-scene impostors (render/passes/impostor/trace.glsl, issue 6): the ONLY units and
// binding points traceSurroundings() uses; consumer shaders must leave them alone. trace.glsl
// spells the same numbers in its layout(binding = N) qualifiers.
inline constexpr unsigned kBindingImpostorCubePosition = 16,  // sampler2DArray, RGBA32F
    kBindingImpostorCubeNormal = 17,                          // sampler2DArray, RGBA16F
    kBindingImpostorCubeAlbedo = 18,                          // sampler2DArray, RGBA8
    kBindingImpostorCubeEmissive = 19,                        // sampler2DArray, RGBA16F
    kBindingImpostorDepth = 20,                               // sampler2DArray, RG32F
    kBindingImpostorNormal = 21,                              // sampler2DArray, RGBA16F
    kBindingImpostorAlbedo = 22,                              // sampler2DArray, RGBA8
    kBindingImpostorEmissive = 23,                            // sampler2DArray, RGBA16F
    kBindingImpostorRecords = 6,                              // SSBO of GpuImpostor
    kBindingImpostorObjects = 7;                              // SSBO: header + GpuImpostorObject

struct alignas(16) GpuLight {
    glm::mat4 viewProj[6];
    glm::vec4 positionRange;
    glm::vec4 directionType;
    glm::vec4 radiantIntensity;
    glm::vec4 cone;
    glm::ivec4 shadow;
};
static_assert(sizeof(GpuLight) == 6 * 64 + 5 * 16);

struct alignas(16) GpuFrame {
    glm::mat4 viewMatrix, projMatrix, viewProj, prevViewProj;
    glm::vec4 cameraPos, prevCameraPos, canvas;
    glm::ivec4 counts, flags;
    glm::vec4 params;
    glm::vec4 envSH[9];
    glm::vec4 exposure;
};
static_assert(sizeof(GpuFrame) == 4 * 64 + 3 * 16 + 2 * 16 + 16 + 9 * 16 + 16);

struct GpuLightBlock {
    GpuLight lights[kMaxLights];
};

struct GpuVpl {
    glm::vec4 positionReal, normal, flux, tangent;
};
static_assert(sizeof(GpuVpl) == 64);

struct GpuMaterial {
    glm::vec4 baseColor, emissive, params;
};
static_assert(sizeof(GpuMaterial) == 48);

// A surface sample for imperfect shadow maps (std430, binding kBindingIsmPoints).
struct GpuSurfacePoint {
    glm::vec4 positionReal;  // xyz world (metres); w = 1 if the geometry is real, 0 if virtual
};

}  // namespace mirage::render
