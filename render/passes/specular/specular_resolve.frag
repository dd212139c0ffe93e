#version 450 core
#include "common.glsl"
#include "passes/specular/specular.glsl"
// Upsample of the half-resolution specular lighting (specular_light.frag MIRAGE_SPECULAR_HALF) to
// the canvas: L'_rv, L'_r, the reflection's share of L'_r and L_env, as the full-resolution
// variant writes them. Per specular pixel and per hit (reflected, refracted), the four half
// pixels around it (bilinear weights) contribute the hit radiance their representative shaded,
// weighted by how well that representative's hit matches this pixel's (geometryTest = 1):
//   - same specular object (the primary G-buffer's slot) and same hit origin (real / virtual);
//   - the representative's hit within sigma of this hit's tangent plane, sigma = 5 mm + 1 % of
//     the hit's camera distance (metres): a step to another surface (a box edge against the
//     table behind it) is rejected, a neighbour on the same surface is not;
//   - normals agreeing (cos^8).
// Where no neighbour matches, the best-matching one stands in. The result is multiplied back by
// this pixel's hit albedo (+ kSpecularDemodulationFloor) and Fresnel weight, its hit's emission
// is added (Eq. 5 routing as the full variant), and L_env is looked up at full resolution.
// geometryTest = 0 (tests only): plain bilinear weights over the half pixels with a
// representative, whatever their geometry (shows halos at depth steps).
#ifdef MIRAGE_REFLECTION_ONLY  // the mirrors' rectangles: no refraction (specular_light.frag)
const int kComponents = 1;
#else
const int kComponents = 2;
#endif
in vec2 uv;
layout(binding = kUnitSpecLightReflFirst) uniform sampler2D reflPosition;
layout(binding = kUnitSpecLightReflFirst + 1) uniform sampler2D reflNormal;
layout(binding = kUnitSpecLightReflFirst + 2) uniform sampler2D reflAlbedo;
layout(binding = kUnitSpecLightReflFirst + 3) uniform sampler2D reflEmissive;
layout(binding = kUnitSpecLightReflFirst + 4) uniform sampler2D reflWeight;
layout(binding = kUnitSpecLightRefrFirst) uniform sampler2D refrPosition;
layout(binding = kUnitSpecLightRefrFirst + 1) uniform sampler2D refrNormal;
layout(binding = kUnitSpecLightRefrFirst + 2) uniform sampler2D refrAlbedo;
layout(binding = kUnitSpecLightRefrFirst + 3) uniform sampler2D refrEmissive;
layout(binding = kUnitSpecLightRefrFirst + 4) uniform sampler2D refrWeight;
layout(binding = kUnitSpecResolveHalfFirst) uniform sampler2D halfReflRv;  // a: 1 + rep index
layout(binding = kUnitSpecResolveHalfFirst + 1) uniform sampler2D halfReflR;
layout(binding = kUnitSpecResolveHalfFirst + 2) uniform sampler2D halfRefrRv;
layout(binding = kUnitSpecResolveHalfFirst + 3) uniform sampler2D halfRefrR;
layout(binding = kUnitSpecResolveSlot) uniform sampler2D gEmissive;  // a = specular slot + 1
layout(binding = kUnitEnvironmentMap) uniform sampler2D envMap;
uniform int geometryTest;
layout(location = 0) out vec4 outRv;     // L'_rv
layout(location = 1) out vec4 outR;      // L'_r
layout(location = 2) out vec4 outRRefl;  // the reflection's share of L'_r
layout(location = 3) out vec4 outEnv;    // L_env; a = 1 on specular pixels
layout(location = 4) out vec4 outHits;   // the full variant's history hits: unused here (0)

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    outRv = vec4(0.0);
    outR = vec4(0.0);
    outRRefl = vec4(0.0);
    outEnv = vec4(0.0);
    outHits = vec4(0.0);
    if (texelFetch(reflEmissive, px, 0).a < 0.5) return;  // not a specular pixel
    float slot = texelFetch(gEmissive, px, 0).a;
    // The four half pixels around this pixel's centre, their bilinear weights and representatives
    // (canvas pixels); weight 0 for a half pixel without one.
    vec2 hc = (vec2(px) + 0.5) * 0.5 - 0.5;
    ivec2 q0 = ivec2(floor(hc)), halfSize = textureSize(halfReflRv, 0);
    vec2 f = hc - vec2(q0);
    ivec2 q[4], rep[4];
    float bilinear[4];
    bool sameSlot[4];
    for (int c = 0; c < 4; ++c) {
        ivec2 o = ivec2(c & 1, c >> 1);
        q[c] = clamp(q0 + o, ivec2(0), halfSize - 1);
        int idx = int(texelFetch(halfReflRv, q[c], 0).a + 0.5) - 1;
        rep[c] = 2 * q[c] + ivec2(max(idx, 0) & 1, max(idx, 0) >> 1);
        float b = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
        bilinear[c] = idx >= 0 ? b : 0.0;
        sameSlot[c] = abs(texelFetch(gEmissive, rep[c], 0).a - slot) < 0.5;
    }
    vec3 rv = vec3(0.0), r = vec3(0.0), rRefl = vec3(0.0), env = vec3(0.0);
    for (int k = 0; k < kComponents; ++k) {
        vec4 P = k == 0 ? texelFetch(reflPosition, px, 0) : texelFetch(refrPosition, px, 0);
        vec3 w = (k == 0 ? texelFetch(reflWeight, px, 0) : texelFetch(refrWeight, px, 0)).rgb;
        if (all(lessThanEqual(w, vec3(0.0)))) continue;
        int origin = int(P.w + 0.5);
        if (origin == ORIGIN_NONE) {
            if (dot(P.xyz, P.xyz) > 0.25) env += w * environmentRadiance(envMap, P.xyz);
            continue;
        }
        vec3 N = (k == 0 ? texelFetch(reflNormal, px, 0) : texelFetch(refrNormal, px, 0)).xyz;
        vec3 A = (k == 0 ? texelFetch(reflAlbedo, px, 0) : texelFetch(refrAlbedo, px, 0)).rgb;
        vec3 e = (k == 0 ? texelFetch(reflEmissive, px, 0) : texelFetch(refrEmissive, px, 0)).rgb;
        float sigma = 0.005 + 0.01 * distance(cameraPos.xyz, P.xyz);
        vec3 sumRv = vec3(0.0), sumR = vec3(0.0), bestRv = vec3(0.0), bestR = vec3(0.0);
        float sumW = 0.0, bestScore = -1.0;
        for (int c = 0; c < 4; ++c) {
            ivec2 rc = rep[c], qc = q[c];
            vec4 Pc = k == 0 ? texelFetch(reflPosition, rc, 0) : texelFetch(refrPosition, rc, 0);
            vec3 Nc = (k == 0 ? texelFetch(reflNormal, rc, 0) : texelFetch(refrNormal, rc, 0)).xyz;
            vec3 hrv = (k == 0 ? texelFetch(halfReflRv, qc, 0) : texelFetch(halfRefrRv, qc, 0)).rgb;
            vec3 hr = (k == 0 ? texelFetch(halfReflR, qc, 0) : texelFetch(halfRefrR, qc, 0)).rgb;
            float plane = dot(N, Pc.xyz - P.xyz) / sigma;
            float geometry = int(Pc.w + 0.5) == origin && sameSlot[c]
                                 ? exp(-min(plane * plane, 30.0)) * pow(max(dot(N, Nc), 0.0), 8.0)
                                 : 0.0;
            float wc = bilinear[c] * (geometryTest != 0 ? geometry : 1.0);
            sumRv += wc * hrv;
            sumR += wc * hr;
            sumW += wc;
            float score = bilinear[c] > 0.0 ? geometry + 1e-3 * bilinear[c] : -1.0;
            if (score > bestScore) {
                bestScore = score;
                bestRv = hrv;
                bestR = hr;
            }
        }
        vec3 hitRv = sumW > 1e-6 ? sumRv / sumW : bestRv;
        vec3 hitR = sumW > 1e-6 ? sumR / sumW : bestR;
        vec3 modulate = A + kSpecularDemodulationFloor;
        vec3 hrvFull = hitRv * modulate + e;
        vec3 hrFull = hitR * modulate + (origin == ORIGIN_REAL ? e : vec3(0.0));
        rv += w * hrvFull;
        r += w * hrFull;
        if (k == 0) rRefl = w * hrFull;
    }
    outRv = vec4(allFinite(rv) ? rv : vec3(0.0), 1.0);
    outR = vec4(allFinite(r) ? r : vec3(0.0), 1.0);
    outRRefl = vec4(allFinite(rRefl) ? rRefl : vec3(0.0), 1.0);
    outEnv = vec4(allFinite(env) ? env : vec3(0.0), 1.0);
}
