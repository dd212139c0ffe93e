#version 450 core
#include "common.glsl"
#include "passes/caustic/caustic.glsl"
// World-space photon grid, step 3 of 3: every photon writes its record (receiver hit, kernel
// radius, powers for L_rv and L_r, receiver normal) into its slot's range (its bucket's, at its
// level), taking a place by counting the slot's count back down to zero (ready for the next
// build). The order within a slot varies with the atomics; the gather reads whole slots. One invocation per
// photon texel, as photon_grid_count.comp (the same photons: photonPowers decides for both).
//
// Kernel radius: causticQuadScale x the photon's spacing to its neighbours on the receiver (the
// caustic splat's footprint, Wyman 2008), at most half a cell (the gather visits the 2x2x2
// cells around a point, which hold every photon within half a cell of it). The gather widens a
// kernel to its own point's footprint.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = kUnitGridReflHit) uniform sampler2DArray reflHit;
layout(binding = kUnitGridReflPower) uniform sampler2DArray reflPower;
layout(binding = kUnitGridReflSurface) uniform usampler2DArray reflSurface;
layout(binding = kUnitGridRefrHit) uniform sampler2DArray refrHit;
layout(binding = kUnitGridRefrPower) uniform sampler2DArray refrPower;
layout(binding = kUnitGridRefrSurface) uniform usampler2DArray refrSurface;
layout(std430, binding = kBindingPhotonGrid) buffer PhotonGridCells { uint grid[]; };
layout(std430, binding = kBindingPhotons) writeonly buffer PhotonRecords { GpuPhoton photons[]; };
uniform int mapSize;
uniform float cellSize;    // m
uniform float quadScale;   // kernel radius in photon spacings
uniform uint capacity;     // photon records allocated

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (t.x >= mapSize || t.y >= mapSize) return;
    bool refracted = (gl_GlobalInvocationID.z & 1u) == 1u;
    ivec3 tl = ivec3(t, int(gl_GlobalInvocationID.z) / 2);
    vec4 hit = refracted ? texelFetch(refrHit, tl, 0) : texelFetch(reflHit, tl, 0);
    vec4 pw = refracted ? texelFetch(refrPower, tl, 0) : texelFetch(reflPower, tl, 0);
    vec3 powerRv, powerR;
    if (!photonPowers(hit, pw, powerRv, powerR)) return;
    float spacing = refracted ? photonSpacing(refrHit, tl, mapSize, hit.xyz)
                              : photonSpacing(reflHit, tl, mapSize, hit.xyz);
    uvec4 sf = refracted ? texelFetch(refrSurface, tl, 0) : texelFetch(reflSurface, tl, 0);
    vec3 n = vec3(unpackHalf2x16(sf.x), unpackHalf2x16(sf.y).x);
    n = dot(n, n) > 1e-12 ? normalize(n) : vec3(0.0, 1.0, 0.0);
    int s = photonSlot(photonBucketAt(hit.xyz, cellSize), photonLevel(t));
    uint place = atomicAdd(grid[s], 0xFFFFFFFFu) - 1u;  // counts down: 0 .. count - 1
    uint index = grid[uint(kPhotonGridSlots) + uint(s)] + place;
    if (index >= capacity) return;
    GpuPhoton p;
    p.position = hit.xyz;
    p.radius = min(quadScale * spacing, 0.5 * cellSize);
    p.powerRv = powerRv;
    p.normal = packNormalOct(n);
    p.powerR = powerR;
    p.pad0 = 0.0;
    photons[index] = p;
}
