#version 450 core
#include "common.glsl"
#include "passes/caustic/caustic.glsl"
// World-space photon grid, step 1 of 3 (count, prefix sum, scatter): every photon of the photon
// G-buffers counts itself into its slot: the hash bucket of the grid cell holding its receiver
// hit, and its level in that bucket (photonLevel of its texel). One invocation per photon texel;
// z = 2 x light layer + (0 reflected, 1 refracted). The counts (grid[0 .. kPhotonGridSlots - 1])
// start at zero: cleared before the first build, and the scatter step counts them back down.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = kUnitGridReflHit) uniform sampler2DArray reflHit;
layout(binding = kUnitGridReflPower) uniform sampler2DArray reflPower;
layout(binding = kUnitGridRefrHit) uniform sampler2DArray refrHit;
layout(binding = kUnitGridRefrPower) uniform sampler2DArray refrPower;
layout(std430, binding = kBindingPhotonGrid) buffer PhotonGridCells { uint grid[]; };
uniform int mapSize;
uniform float cellSize;  // m

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (t.x >= mapSize || t.y >= mapSize) return;
    bool refracted = (gl_GlobalInvocationID.z & 1u) == 1u;
    ivec3 tl = ivec3(t, int(gl_GlobalInvocationID.z) / 2);
    vec4 hit = refracted ? texelFetch(refrHit, tl, 0) : texelFetch(reflHit, tl, 0);
    vec4 pw = refracted ? texelFetch(refrPower, tl, 0) : texelFetch(reflPower, tl, 0);
    vec3 powerRv, powerR;
    if (!photonPowers(hit, pw, powerRv, powerR)) return;
    atomicAdd(grid[photonSlot(photonBucketAt(hit.xyz, cellSize), photonLevel(t))], 1u);
}
