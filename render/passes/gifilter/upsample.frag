#version 450 core
#include "common.glsl"
// Joint bilateral upsampling of the filtered, temporally smoothed indirect light (filter.frag,
// gather resolution) to full resolution: the 2 x 2 gather pixels around p, weighted bilinearly
// and by geometry (position / normal match with p), and the sum with direct light: the GI
// solutions L_rv and L_r (linear). Each gather pixel's depth, normal and light come packed by
// filter.frag in one texel (llvmpipe pays per texel read, and this pass reads 4 gather pixels
// for each of the canvas's); its point is rebuilt on its canvas pixel's ray.
in vec2 uv;
layout(binding = kUnitUpsamplePosition) uniform sampler2D gPosition;
layout(binding = kUnitUpsampleNormal) uniform sampler2D gNormal;
layout(binding = kUnitUpsampleGatherLight) uniform usampler2D gatherLight;  // L_rv, L_r, depth, normal
layout(binding = kUnitUpsampleDirectRv) uniform sampler2D directRv;
layout(binding = kUnitUpsampleDirectR) uniform sampler2D directR;
uniform int scale;  // the indirect buffers are at 1/scale resolution (joint bilateral upsampling)
// World direction of canvas pixel (x, y)'s ray, scaled to camera-frame depth 1:
// rayFromPixel * vec3(x, y, 1) (R^T K^-1 on the canvas, pixel centres at integers).
uniform mat3 rayFromPixel;
layout(location = 0) out vec4 outRv;
layout(location = 1) out vec4 outR;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(gPosition, 0);
    vec4 P = texelFetch(gPosition, px, 0);
    vec3 dRv = texelFetch(directRv, px, 0).rgb, dR = texelFetch(directR, px, 0).rgb;
    if (int(P.w + 0.5) == ORIGIN_NONE) {
        outRv = vec4(dRv, 1.0);
        outR = vec4(dR, 1.0);
        return;
    }
    vec3 n = texelFetch(gNormal, px, 0).xyz;
    float camDist = length(P.xyz - cameraPos.xyz);
    // The plane test's distance of a gather point Q = cameraPos + z (rayFromPixel (x, y, 1)) from
    // p's tangent plane, dot(Q - p, n), is z (x nx + y ny + n1) - np: linear in the gather
    // pixel's (x, y), with these four per pixel (a few operations per tap instead of a 3 x 3
    // product and a dot product).
    float nx = dot(rayFromPixel[0], n), ny = dot(rayFromPixel[1], n);
    float n1 = dot(rayFromPixel[2], n), np = dot(P.xyz - cameraPos.xyz, n);
    float invTolerance = 1.0 / max(0.01 * camDist, 1e-4);
    ivec2 lowSize = textureSize(gatherLight, 0);
    vec2 f = canvasToGather(vec2(px), scale);  // p in gather pixel coordinates
    ivec2 c0 = ivec2(floor(f));
    vec2 fr = f - vec2(c0);
    vec3 sumRv = vec3(0.0), sumR = vec3(0.0);
    float wsum = 0.0;
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        ivec2 q = clamp(c0 + o, ivec2(0), lowSize - 1);
        uvec4 L = texelFetch(gatherLight, q, 0);
        float zq = unpackHalf2x16(L.w).x;
        if (zq <= 0.0) continue;  // no surface there
        vec3 nq = unpackNormalOct8(L.w >> 16);
        vec2 cq = vec2(gatherCanvasPixel(q, scale, size));
        float planeDist = abs(zq * (cq.x * nx + cq.y * ny + n1) - np) * invTolerance;
        float cs = max(dot(n, nq), 0.0);
        cs *= cs;
        cs *= cs;
        cs *= cs;
        cs *= cs;
        float geom = cs / (1.0 + planeDist * planeDist * 4.0);
        float bil = (o.x == 1 ? fr.x : 1.0 - fr.x) * (o.y == 1 ? fr.y : 1.0 - fr.y);
        float w = geom * (bil + 1e-3);  // a rejected bilinear tap leaves the others in charge
        vec2 l0 = unpackHalf2x16(L.x), l1 = unpackHalf2x16(L.y), l2 = unpackHalf2x16(L.z);
        sumRv += w * vec3(l0, l1.x);
        sumR += w * vec3(l1.y, l2);
        wsum += w;
    }
    vec3 iRv = wsum > 1e-6 ? sumRv / wsum : vec3(0.0);
    vec3 iR = wsum > 1e-6 ? sumR / wsum : vec3(0.0);
    outRv = vec4(dRv + iRv, 1.0);
    outR = vec4(dR + iR, 1.0);
}
