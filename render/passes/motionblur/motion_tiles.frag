#version 450 core
#include "common.glsl"
// TileMax of the reconstruction filter (McGuire et al. 2012): per tile of tileSize x tileSize
// camera pixels, the largest half motion (rg), and whether the renderer changed any pixel of the
// tile (b = 1: a virtual or mirror / glass pixel, or a real pixel whose composite differs from its
// footage by more than `changeEpsilon`; 0: the footage alone, which the camera already blurred).
layout(binding = kUnitMotionVelocity) uniform sampler2D velocity;
layout(binding = kUnitMotionComposite) uniform sampler2D composite;
layout(binding = kUnitMotionFootage) uniform sampler2D footage;
uniform int tileSize;
uniform float changeEpsilon;  // camera linear units
layout(location = 0) out vec4 outTile;

void main() {
    ivec2 size = textureSize(velocity, 0);
    ivec2 origin = ivec2(gl_FragCoord.xy) * tileSize;
    vec2 best = vec2(0.0);
    float bestLength2 = 0.0;
    float changed = 0.0;
    for (int y = 0; y < tileSize; ++y)
        for (int x = 0; x < tileSize; ++x) {
            ivec2 p = min(origin + ivec2(x, y), size - 1);
            vec2 v = texelFetch(velocity, p, 0).xy;
            float l2 = dot(v, v);
            if (l2 > bestLength2) {
                bestLength2 = l2;
                best = v;
            }
            vec4 f = texelFetch(footage, p, 0);
            vec3 d = abs(texelFetch(composite, p, 0).rgb - f.rgb);
            if (f.a > 0.5 || max(d.r, max(d.g, d.b)) > changeEpsilon) changed = 1.0;
        }
    outTile = vec4(best, changed, 1.0);
}
