#version 450 core
#include "common.glsl"
// Joint bilateral upsampling of the filtered indirect light (deinterleave.frag, gather
// resolution) to full resolution: the 2 x 2 gather pixels around p, weighted bilinearly and by
// geometry (position / normal match with p), temporal smoothing against VPL flicker (history reprojected with last
// frame's camera, rejected where the surface there is at a different distance; off after a cut
// or tracking loss), and the sum with direct light: the GI solutions L_rv and L_r (linear).
in vec2 uv;
layout(binding = 0) uniform sampler2D gPosition;
layout(binding = 1) uniform sampler2D gNormal;
layout(binding = 2) uniform sampler2D indirectRv;  // filtered, gather resolution
layout(binding = 3) uniform sampler2D indirectR;
layout(binding = 4) uniform sampler2D directRv;
layout(binding = 5) uniform sampler2D directR;
layout(binding = 6) uniform sampler2D historyRv;  // rgb filtered indirect, a = camera distance
layout(binding = 7) uniform sampler2D historyR;
uniform int scale;  // the indirect buffers are at 1/scale resolution (joint bilateral upsampling)
layout(location = 0) out vec4 outRv;
layout(location = 1) out vec4 outR;
layout(location = 2) out vec4 outHistoryRv;
layout(location = 3) out vec4 outHistoryR;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(gPosition, 0);
    vec4 P = texelFetch(gPosition, px, 0);
    vec3 dRv = texelFetch(directRv, px, 0).rgb, dR = texelFetch(directR, px, 0).rgb;
    if (int(P.w + 0.5) == ORIGIN_NONE) {
        outRv = vec4(dRv, 1.0);
        outR = vec4(dR, 1.0);
        outHistoryRv = vec4(0.0);
        outHistoryR = vec4(0.0);
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
    if (flags.y == 1 && params.z > 0.0) {
        vec4 prev = prevViewProj * vec4(P.xyz, 1.0);
        if (prev.w > 1e-6) {
            vec2 puv = prev.xy / prev.w * 0.5 + 0.5;
            if (all(greaterThanEqual(puv, vec2(0.0))) && all(lessThanEqual(puv, vec2(1.0)))) {
                vec4 hRv = texture(historyRv, puv);
                vec4 hR = texture(historyR, puv);
                float expected = length(P.xyz - prevCameraPos.xyz);
                if (abs(hRv.a - expected) < 0.02 * expected + 0.005 && allFinite(hRv.rgb) &&
                    allFinite(hR.rgb)) {
                    iRv = mix(iRv, hRv.rgb, params.z);
                    iR = mix(iR, hR.rgb, params.z);
                }
            }
        }
    }
    outHistoryRv = vec4(iRv, camDist);
    outHistoryR = vec4(iR, camDist);
    outRv = vec4(dRv + iRv, 1.0);
    outR = vec4(dR + iR, 1.0);
}
