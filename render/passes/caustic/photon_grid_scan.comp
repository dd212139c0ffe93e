#version 450 core
#include "common.glsl"
// World-space photon grid, step 2 of 3: the exclusive prefix sum of the slot counts (a slot per
// bucket and level, photonSlot), so that slot s's photons will sit at [first[s], first[s + 1])
// of the photon records, with first = grid[kPhotonGridSlots ..] (kPhotonGridSlots + 1 entries;
// the last is the total). One work group: each invocation sums a run of slots, one invocation
// scans the runs' totals.
layout(local_size_x = 256) in;
layout(std430, binding = kBindingPhotonGrid) buffer PhotonGridCells { uint grid[]; };
shared uint runStart[256];
const uint kRun = uint(kPhotonGridSlots) / 256u;

void main() {
    uint i = gl_LocalInvocationID.x;
    uint sum = 0u;
    for (uint k = 0u; k < kRun; ++k) sum += grid[i * kRun + k];
    runStart[i] = sum;
    memoryBarrierShared();
    barrier();
    if (i == 0u) {
        uint acc = 0u;
        for (uint j = 0u; j < 256u; ++j) {
            uint v = runStart[j];
            runStart[j] = acc;
            acc += v;
        }
        grid[2 * kPhotonGridSlots] = acc;
    }
    memoryBarrierShared();
    barrier();
    uint acc = runStart[i];
    for (uint k = 0u; k < kRun; ++k) {
        uint b = i * kRun + k;
        grid[uint(kPhotonGridSlots) + b] = acc;
        acc += grid[b];
    }
}
