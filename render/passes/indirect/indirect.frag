#version 450 core
#include "common.glsl"
// One indirect bounce from the VPLs with interleaved sampling (Keller & Heidrich 2001): gather
// pixel q = (x, y) sums only VPLs i = g, g + K^2, ... with g = (x mod K) + K (y mod K), scaled by
// K^2; the geometry-aware filter then recombines the K x K groups. The output is DEINTERLEAVED:
// tile (x mod K, y mod K) of the target holds group g's pixels at (x / K, y / K), and each tile is
// one draw with `group` uniform. Visibility from the imperfect shadow maps. Routing
// (docs/realtime-renderer.md, "Real and virtual: routing"): a VPL at q lights p in L_rv always;
// in L_r only if the light, q and p are all real, with visibility against real points only.
// Diffuse receivers.
in vec2 uv;
layout(binding = kUnitIndirectVpls) uniform samplerBuffer vplTexels;  // GpuVpl[] (vplAt)
layout(binding = kUnitIndirectPosition) uniform sampler2D gPosition;
layout(binding = kUnitIndirectNormal) uniform sampler2D gNormal;
layout(binding = kUnitIndirectAlbedo) uniform sampler2D gAlbedo;
layout(binding = kUnitIndirectIsmAll) uniform usampler2D ismAll;
layout(binding = kUnitIndirectIsmReal) uniform usampler2D ismReal;
uniform int scale;  // gather pixel q shades G-buffer pixel gatherCanvasPixel(q, scale)
uniform ivec2 group;       // (x mod K, y mod K) of this draw's pixels
uniform ivec2 tileOrigin;  // where this group's tile starts in the target
layout(location = 0) out vec4 outRv;
layout(location = 1) out vec4 outR;


void main() {
    int K = max(interleave, 1);
    ivec2 q = (ivec2(gl_FragCoord.xy) - tileOrigin) * K + group;  // interleaved gather pixel
    ivec2 g = gatherCanvasPixel(q, scale, textureSize(gPosition, 0));
    vec4 P = texelFetch(gPosition, g, 0);
    int origin = int(P.w + 0.5);
    outRv = vec4(0.0);
    outR = vec4(0.0);
    if (origin == ORIGIN_NONE) return;
    bool pReal = origin == ORIGIN_REAL;
    vec3 p = P.xyz;
    vec3 n = texelFetch(gNormal, g, 0).xyz;
    vec4 A = texelFetch(gAlbedo, g, 0);
    vec3 diffuse = A.rgb * (1.0 - A.a) / PI;
    int first = group.x + K * group.y;
    float clamp2 = vplDistanceClamp * vplDistanceClamp;
    vec3 rv = vec3(0.0), r = vec3(0.0);
    for (int i = first; i < vplCount; i += K * K) {
        GpuVpl V = vplAt(vplTexels, i);
        if (V.valid == 0) continue;
        vec3 d = p - V.position;
        float dist2 = dot(d, d);
        if (dist2 < 1e-10) continue;
        float dist = sqrt(dist2);
        vec3 w = d / dist;
        float cosQ = dot(V.normal, w), cosP = dot(n, -w);
        if (cosQ <= 0.0 || cosP <= 0.0) continue;
        vec3 c = diffuse * V.flux / PI * cosQ * cosP / max(dist2, clamp2);
        float bias = 0.02 + 0.03 * dist;
        vec2 puv = paraboloidUv(V, w);
        bool visAll = dist - bias <= ismDistance(ismAll, i, puv);
        if (visAll) rv += c;
        if (V.isReal != 0 && pReal) {
            bool visReal = dist - bias <= ismDistance(ismReal, i, puv);
            if (visReal) r += c;
        }
    }
    float groupScale = float(K * K);
    outRv = vec4(allFinite(rv) ? rv * groupScale : vec3(0.0), 1.0);
    outR = vec4(allFinite(r) ? r * groupScale : vec3(0.0), 1.0);
}
