#version 450 core
#include "common.glsl"
// Imperfect shadow maps (Ritschel et al. 2008): each VPL splats its own subset of the scene's
// surface point pool into a small paraboloid depth tile around its normal. Scattering points is
// an order of magnitude cheaper as compute + imageAtomicMin than as GL_POINTS on llvmpipe.
// Depth = distance to the VPL in metres, stored as float bits in r32ui
// (positive floats order like unsigned ints). The real-only atlas gets only the real points.
layout(local_size_x = 64) in;
layout(std430, binding = kBindingVpls) readonly buffer Vpls { GpuVpl vpls[]; };
layout(std430, binding = kBindingIsmPoints) readonly buffer Points { GpuSurfacePoint points[]; };
layout(r32ui, binding = kImageIsmAll) uniform coherent uimage2D ismAll;
layout(r32ui, binding = kImageIsmReal) uniform coherent uimage2D ismReal;
uniform int pointCount;       // size of the pool
uniform int writeReal;        // 1: also fill the real-only atlas
uniform float pointRadius;    // metres: radius of the disc one splatted point stands for

void splat(int vplIndex, vec3 p, bool real) {
    GpuVpl v = vpls[vplIndex];
    if (v.valid == 0) return;
    vec3 n = v.normal;
    vec3 d = p - v.position;
    float dist = length(d);
    if (dist < 1e-4) return;
    vec3 w = d / dist;
    float z = dot(w, n);
    if (z <= 0.0) return;  // behind the VPL's cosine lobe: never lit by it
    vec2 uv = paraboloidUv(v, w);
    int tile = ismTileSize, perRow = ismTilesPerRow;
    ivec2 origin = ivec2(vplIndex % perRow, vplIndex / perRow) * tile;
    vec2 texel = (uv * 0.5 + 0.5) * float(tile);
    int r = int(clamp(pointRadius / dist * 0.5 * float(tile) / (1.0 + z), 0.0, 2.0));
    uint depth = floatBitsToUint(dist);
    for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
            ivec2 q = ivec2(texel) + ivec2(dx, dy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, ivec2(tile)))) continue;
            imageAtomicMin(ismAll, origin + q, depth);
            if (real && writeReal == 1) imageAtomicMin(ismReal, origin + q, depth);
        }
}

void main() {
    int perVpl = int(ismPointsPerVpl);
    int id = int(gl_GlobalInvocationID.x);
    int vplIndex = id / perVpl;
    if (vplIndex >= vplCount || pointCount <= 0) return;
    int j = id % perVpl;
    // Each VPL reads a different contiguous window of the shuffled pool.
    int pi = (vplIndex * 7919 + j) % pointCount;
    GpuSurfacePoint pt = points[pi];
    splat(vplIndex, pt.position, pt.isReal != 0);
}
