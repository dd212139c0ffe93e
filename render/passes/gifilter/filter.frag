#version 450 core
#include "common.glsl"
#include "temporal.glsl"
// Geometry-aware filter of the interleaved indirect light, at gather resolution: a K x K window
// around gather pixel c holds one pixel of every VPL group; neighbours count only if their
// position and normal match c's (weights: cos^16 of the normal difference, distance from c's
// tangent plane relative to 1 % of the camera distance), so light does not bleed across edges.
// Then temporal smoothing against VPL flicker, also at gather resolution (a quarter of the
// pixels of doing it after upsampling): history reprojected with last frame's camera, rejected
// where the surface there is at a different distance; off after a cut or tracking loss.
// Reads the deinterleaved layout of indirect.frag; writes the normal (interleaved) layout.
#ifndef MIRAGE_INTERLEAVE  // GiFilterPass sets it from RendererOptions::interleave
#define MIRAGE_INTERLEAVE 4
#endif
// K is a compile-time constant so that the K x K loop unrolls: llvmpipe runs a loop with a
// uniform-buffer bound as a masked SIMD loop, 1.4x slower for this pass.
in vec2 uv;
layout(binding = kUnitFilterPosition) uniform sampler2D gPosition;
layout(binding = kUnitFilterNormal) uniform sampler2D gNormal;
layout(binding = kUnitFilterIndirectRv) uniform sampler2D indirectRv;  // deinterleaved, size a multiple of K
layout(binding = kUnitFilterIndirectR) uniform sampler2D indirectR;
layout(binding = kUnitFilterHistoryRv) uniform sampler2D historyRv;  // gather res: rgb filtered, a = camera dist.
layout(binding = kUnitFilterHistoryR) uniform sampler2D historyR;
uniform int scale;  // gather pixel q was shaded at G-buffer pixel gatherCanvasPixel(q, scale)
uniform float historyWeight;  // the history's share; 0: none this frame (TemporalHistory)
layout(location = 0) out vec4 outRv;  // rgb filtered + smoothed; a = camera distance (m)
layout(location = 1) out vec4 outR;   // (the history of the next frame)
// The same light packed for the upsample (passes/direct/gi_upsample.glsl), which reads 4
// gather pixels per canvas pixel: one texel per gather pixel instead of four (its G-buffer
// position and normal, L_rv, L_r). The position is the camera-frame depth along the gather
// pixel's ray (the upsample rebuilds the point): half precision is 0.05 % of it, far below the
// 1 % of the camera distance the upsample's plane test tolerates.
layout(location = 2) out uvec4 outUpsampleLight;  // L_rv, L_r as 6 halves; w: see packGather

// Camera-frame depth z (m, half; 0: no surface) in the low 16 bits, the normal (8-bit oct) in
// the high 16.
uint packGather(float z, vec3 n) {
    return (packHalf2x16(vec2(z, 0.0)) & 0xFFFFu) | (packNormalOct8(n) << 16);
}

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
    ivec2 cg = gatherCanvasPixel(c, scale, size);
    vec4 P = texelFetch(gPosition, cg, 0);
    outRv = vec4(0.0);
    outR = vec4(0.0);
    outUpsampleLight = uvec4(0u);
    if (int(P.w + 0.5) == ORIGIN_NONE) return;
    vec3 n = texelFetch(gNormal, cg, 0).xyz;
    float camDist = length(P.xyz - cameraPos.xyz);
    const int K = MIRAGE_INTERLEAVE;
    ivec2 lowSize = textureSize(indirectRv, 0);
    ivec2 tile = lowSize / K;
    vec3 sumRv = vec3(0.0), sumR = vec3(0.0);
    float wsum = 0.0;
    for (int dy = -K / 2; dy < K - K / 2; ++dy)
        for (int dx = -K / 2; dx < K - K / 2; ++dx) {
            ivec2 q = clamp(c + ivec2(dx, dy), ivec2(0), lowSize - 1);
            ivec2 qg = gatherCanvasPixel(q, scale, size);
            vec4 Q = texelFetch(gPosition, qg, 0);
            if (int(Q.w + 0.5) == ORIGIN_NONE) continue;
            float w = geometryWeight(P.xyz, n, camDist, Q.xyz, texelFetch(gNormal, qg, 0).xyz);
            ivec2 t = (q % K) * tile + q / K;
            sumRv += w * texelFetch(indirectRv, t, 0).rgb;
            sumR += w * texelFetch(indirectR, t, 0).rgb;
            wsum += w;
        }
    vec3 iRv = wsum > 1e-6 ? sumRv / wsum : vec3(0.0);
    vec3 iR = wsum > 1e-6 ? sumR / wsum : vec3(0.0);
    vec2 puv;
    if (historyWeight > 0.0 && reprojectToPreviousFrame(P.xyz, puv)) {
        // Canvas position -> gather texture coordinate.
        vec2 hp = canvasToGather(puv * vec2(size) - 0.5, scale);
        vec2 huv = (hp + 0.5) / vec2(textureSize(historyRv, 0));
        vec4 hRv = texture(historyRv, huv);
        vec4 hR = texture(historyR, huv);
        if (historyIsSameSurface(hRv.a, P.xyz) && allFinite(hRv.rgb) && allFinite(hR.rgb)) {
            iRv = mix(iRv, hRv.rgb, historyWeight);
            iR = mix(iR, hR.rgb, historyWeight);
        }
    }
    outRv = vec4(iRv, camDist);
    outR = vec4(iR, camDist);
    float z = max((viewMatrix * vec4(P.xyz, 1.0)).z, 1e-4);  // > 0: a surface
    outUpsampleLight = uvec4(packHalf2x16(iRv.rg), packHalf2x16(vec2(iRv.b, iR.r)),
                             packHalf2x16(iR.gb), packGather(z, n));
}
