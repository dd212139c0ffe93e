#version 450 core
#include "common.glsl"
// Geometry-aware filter of the interleaved indirect light, at gather resolution: a K x K window
// around gather pixel c holds one pixel of every VPL group; neighbours count only if their
// position and normal match c's (weights: cos^16 of the normal difference, distance from c's
// tangent plane relative to 1 % of the camera distance), so light does not bleed across edges.
// Reads the deinterleaved layout of indirect.frag; writes the normal (interleaved) layout.
in vec2 uv;
layout(binding = 0) uniform sampler2D gPosition;
layout(binding = 1) uniform sampler2D gNormal;
layout(binding = 2) uniform sampler2D indirectRv;  // deinterleaved, size a multiple of K
layout(binding = 3) uniform sampler2D indirectR;
uniform int scale;  // gather pixel q was shaded at G-buffer pixel q * scale
layout(location = 0) out vec4 outRv;
layout(location = 1) out vec4 outR;

float geometryWeight(vec3 p, vec3 n, float camDist, vec3 q, vec3 nq) {
    float planeDist = abs(dot(q - p, n)) / max(0.01 * camDist, 1e-4);
    float c = max(dot(n, nq), 0.0);
    c *= c;
    c *= c;
    c *= c;
    c *= c;  // cos^16: ~0.5 at 17 degrees
    return c / (1.0 + planeDist * planeDist * 4.0);
}

void main() {
    ivec2 c = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(gPosition, 0);
    vec4 P = texelFetch(gPosition, min(c * scale, size - 1), 0);
    outRv = vec4(0.0);
    outR = vec4(0.0);
    if (int(P.w + 0.5) == ORIGIN_NONE) return;
    vec3 n = texelFetch(gNormal, min(c * scale, size - 1), 0).xyz;
    float camDist = length(P.xyz - cameraPos.xyz);
    int K = max(counts.z, 1);
    ivec2 lowSize = textureSize(indirectRv, 0);
    ivec2 tile = lowSize / K;
    vec3 sumRv = vec3(0.0), sumR = vec3(0.0);
    float wsum = 0.0;
    for (int dy = -K / 2; dy < K - K / 2; ++dy)
        for (int dx = -K / 2; dx < K - K / 2; ++dx) {
            ivec2 q = clamp(c + ivec2(dx, dy), ivec2(0), lowSize - 1);
            ivec2 qg = min(q * scale, size - 1);
            vec4 Q = texelFetch(gPosition, qg, 0);
            if (int(Q.w + 0.5) == ORIGIN_NONE) continue;
            float w = geometryWeight(P.xyz, n, camDist, Q.xyz, texelFetch(gNormal, qg, 0).xyz);
            ivec2 t = (q % K) * tile + q / K;
            sumRv += w * texelFetch(indirectRv, t, 0).rgb;
            sumR += w * texelFetch(indirectR, t, 0).rgb;
            wsum += w;
        }
    if (wsum > 1e-6) {
        outRv = vec4(sumRv / wsum, 1.0);
        outR = vec4(sumR / wsum, 1.0);
    }
}
