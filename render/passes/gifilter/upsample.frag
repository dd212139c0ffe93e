#version 450 core
#include "common.glsl"
// Joint bilateral upsampling of the filtered, temporally smoothed indirect light (filter.frag,
// gather resolution) to full resolution: the 2 x 2 gather pixels around p, weighted bilinearly
// and by geometry (position / normal match with p), and the sum with direct light: the GI
// solutions L_rv and L_r (linear).
in vec2 uv;
layout(binding = kUnitUpsamplePosition) uniform sampler2D gPosition;
layout(binding = kUnitUpsampleNormal) uniform sampler2D gNormal;
layout(binding = kUnitUpsampleIndirectRv) uniform sampler2D indirectRv;  // filtered, gather resolution
layout(binding = kUnitUpsampleIndirectR) uniform sampler2D indirectR;
layout(binding = kUnitUpsampleDirectRv) uniform sampler2D directRv;
layout(binding = kUnitUpsampleDirectR) uniform sampler2D directR;
uniform int scale;  // the indirect buffers are at 1/scale resolution (joint bilateral upsampling)
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
    ivec2 lowSize = textureSize(indirectRv, 0);
    vec2 f = (vec2(px) + 0.5) / float(scale) - 0.5;  // p in gather pixel coordinates
    ivec2 c0 = ivec2(floor(f));
    vec2 fr = f - vec2(c0);
    vec3 sumRv = vec3(0.0), sumR = vec3(0.0);
    float wsum = 0.0;
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        ivec2 q = clamp(c0 + o, ivec2(0), lowSize - 1);
        ivec2 qg = min(q * scale, size - 1);
        vec4 Q = texelFetch(gPosition, qg, 0);
        if (int(Q.w + 0.5) == ORIGIN_NONE) continue;
        vec3 nq = texelFetch(gNormal, qg, 0).xyz;
        float planeDist = abs(dot(Q.xyz - P.xyz, n)) / max(0.01 * camDist, 1e-4);
        float cs = max(dot(n, nq), 0.0);
        cs *= cs;
        cs *= cs;
        cs *= cs;
        cs *= cs;
        float geom = cs / (1.0 + planeDist * planeDist * 4.0);
        float bil = (o.x == 1 ? fr.x : 1.0 - fr.x) * (o.y == 1 ? fr.y : 1.0 - fr.y);
        float w = geom * (bil + 1e-3);  // a rejected bilinear tap leaves the others in charge
        sumRv += w * texelFetch(indirectRv, q, 0).rgb;
        sumR += w * texelFetch(indirectR, q, 0).rgb;
        wsum += w;
    }
    vec3 iRv = wsum > 1e-6 ? sumRv / wsum : vec3(0.0);
    vec3 iR = wsum > 1e-6 ? sumR / wsum : vec3(0.0);
    outRv = vec4(dRv + iRv, 1.0);
    outR = vec4(dR + iR, 1.0);
}
