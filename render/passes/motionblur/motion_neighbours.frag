#version 450 core
#include "common.glsl"
// NeighborMax of the reconstruction filter (McGuire et al. 2012): per tile, the largest half
// motion of the 3 x 3 tiles around it (a pixel's blur reaches at most one tile into its
// neighbours: the motion is clamped to the tile size), and whether any of them was changed by the
// renderer (b).
layout(binding = kUnitMotionTiles) uniform sampler2D tiles;
layout(location = 0) out vec4 outNeighbours;

void main() {
    ivec2 size = textureSize(tiles, 0);
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec2 best = vec2(0.0);
    float bestLength2 = 0.0;
    float changed = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
            vec4 n = texelFetch(tiles, clamp(t + ivec2(x, y), ivec2(0), size - 1), 0);
            float l2 = dot(n.xy, n.xy);
            if (l2 > bestLength2) {
                bestLength2 = l2;
                best = n.xy;
            }
            changed = max(changed, n.z);
        }
    outNeighbours = vec4(best, changed, 1.0);
}
