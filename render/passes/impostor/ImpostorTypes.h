#pragma once
// The impostor tables as C++: render/passes/impostor/impostor_types.glsl is written once, in the
// subset of syntax GLSL and C++ share (render/GpuTypes.h), and included here. std430 offsets are
// checked below.
#include <cstddef>

#include "render/GpuTypes.h"

namespace mirage::render {

#include "render/passes/impostor/impostor_types.glsl"

static_assert(sizeof(GpuImpostor) == 80);
static_assert(offsetof(GpuImpostor, layer) == 12 && offsetof(GpuImpostor, axisU) == 16);
static_assert(offsetof(GpuImpostor, halfV) == 44 && offsetof(GpuImpostor, axisW) == 48);
static_assert(offsetof(GpuImpostor, kind) == 64);
static_assert(sizeof(GpuImpostorObject) == 48);
static_assert(offsetof(GpuImpostorObject, radius) == 12);
static_assert(offsetof(GpuImpostorObject, firstImpostor) == 16);
static_assert(offsetof(GpuImpostorObject, enclosingReach) == 32);
static_assert(sizeof(GpuImpostorHeader) == 32);
static_assert(offsetof(GpuImpostorHeader, cubeResolution) == 16);

}  // namespace mirage::render
