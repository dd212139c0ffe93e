#pragma once
// The GPU data layout and binding points as C++: render/gpu_types.glsl and render/bindings.glsl
// are written once, in the subset of syntax GLSL and C++ share, and included here (vec4 etc. are
// glm's types). std140 / std430 offsets are checked below; never magic numbers in passes.
#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

namespace mirage::render {

using vec3 = glm::vec3;
using vec4 = glm::vec4;
using ivec4 = glm::ivec4;
using mat4 = glm::mat4;

#include "render/gpu_types.glsl"  // includes render/bindings.glsl

static_assert(sizeof(GpuLight) == (6 + kMaxFocusMaps) * 64 + 7 * 16);
static_assert(offsetof(GpuLight, focusFrustumSize) == 6 * 64 + 6 * 16);
static_assert(offsetof(GpuLight, focusViewProj) == 6 * 64 + 7 * 16);
static_assert(offsetof(GpuLight, glassShadow) == 6 * 64 + 5 * 16);
static_assert(offsetof(GpuLight, range) == 6 * 64 + 12 && offsetof(GpuLight, type) == 6 * 64 + 28);
static_assert(offsetof(GpuLight, frustumSize) == 6 * 64 + 44);
static_assert(offsetof(GpuLight, cosOuter) == 6 * 64 + 3 * 16);
static_assert(offsetof(GpuLight, firstShadowLayer) == 6 * 64 + 4 * 16);
static_assert(sizeof(GpuFrame) == 4 * 64 + 3 * 16 + 3 * 16 + 2 * 16);
static_assert(offsetof(GpuFrame, lightCount) == 4 * 64 + 3 * 16);
static_assert(offsetof(GpuFrame, envOrigin) == 4 * 64 + 4 * 16);
static_assert(offsetof(GpuFrame, vplDistanceClamp) == 4 * 64 + 5 * 16);
static_assert(offsetof(GpuFrame, exposure) == 4 * 64 + 6 * 16);
static_assert(offsetof(GpuFrame, alphaMax) == 4 * 64 + 6 * 16 + 12);  // std140: after a vec3
static_assert(sizeof(GpuEnvironment) == 10 * 16);
static_assert(offsetof(GpuEnvironment, envRotation) == 9 * 16);
static_assert(sizeof(GpuLightBlock) == kMaxLights * sizeof(GpuLight));
static_assert(sizeof(GpuVpl) == 64);
static_assert(offsetof(GpuVpl, isReal) == 12 && offsetof(GpuVpl, valid) == 28);
static_assert(offsetof(GpuVpl, tangent) == 48);
static_assert(sizeof(GpuMaterial) == 80);
static_assert(offsetof(GpuMaterial, emissive) == 16 && offsetof(GpuMaterial, roughness) == 28);
static_assert(offsetof(GpuMaterial, metallic) == 32 && offsetof(GpuMaterial, ior) == 40);
static_assert(offsetof(GpuMaterial, attenuationColor) == 48 && offsetof(GpuMaterial, mirror) == 60);
static_assert(offsetof(GpuMaterial, thickness) == 64 && offsetof(GpuMaterial, specular) == 68);
static_assert(offsetof(GpuMaterial, translucent) == 72);
static_assert(sizeof(GpuSpecularDraw) == 32);
static_assert(offsetof(GpuSpecularDraw, radius) == 12 && offsetof(GpuSpecularDraw, material) == 16);
static_assert(sizeof(GpuPhoton) == 48 && offsetof(GpuPhoton, normal) == 28);
static_assert(sizeof(GpuSurfacePoint) == 16 && offsetof(GpuSurfacePoint, isReal) == 12);

}  // namespace mirage::render
