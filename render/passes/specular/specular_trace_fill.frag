#version 450 core
#include "common.glsl"
// Fill of the half-resolution trace (RendererOptions::specular.halfResolutionTrace): GBuf_refl
// and GBuf_refr at canvas resolution from the half-resolution ones, whose every texel holds the
// hits traced from its 2x2 block's representative (the block's first specular pixel,
// specular_gbuffer.frag MIRAGE_SPECULAR_TRACE_HALF). A specular pixel takes the hits of the
// block, among its own and the three nearest around it, whose representative's primary surface
// matches its own best: same specular object (slot), within sigma of this pixel's tangent plane
// (sigma = 2 mm + 0.5 % of the camera distance, metres) and normals agreeing (cos^8), its own
// block winning ties. So the two sides of an object's edge never take each other's hits, and a
// pixel at a silhouette takes a neighbour block's hits on its own object. Every output is the
// representative's (hit, Fresnel weight, distance inside); the specular-pixel flag is this
// pixel's.
in vec2 uv;
layout(binding = kUnitSpecFillHalfFirst) uniform sampler2D halfHits[10];  // refl 0-4, refr 5-9
layout(binding = kUnitSpecFillPosition) uniform sampler2D gPosition;
layout(binding = kUnitSpecFillNormal) uniform sampler2D gNormal;
layout(binding = kUnitSpecFillEmissive) uniform sampler2D gEmissive;  // a = specular slot + 1
#ifndef MIRAGE_SPECULAR_MODE
#define MIRAGE_SPECULAR_MODE 0
#endif
const int mode = MIRAGE_SPECULAR_MODE;  // 0 = reflection, 1 = refraction
layout(location = 0) out vec4 outPosition;
layout(location = 1) out vec4 outNormal;
layout(location = 2) out vec4 outAlbedo;
layout(location = 3) out vec4 outEmissive;
layout(location = 4) out vec4 outWeight;

// The block's representative, as specular_gbuffer.frag chooses it; -1: none.
ivec2 blockRepresentative(ivec2 block) {
    ivec2 size = textureSize(gEmissive, 0);
    for (int i = 0; i < 4; ++i) {
        ivec2 c = 2 * block + ivec2(i & 1, i >> 1);
        if (all(lessThan(c, size)) && texelFetch(gEmissive, c, 0).a >= 0.5) return c;
    }
    return ivec2(-1);
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    outPosition = outNormal = outAlbedo = outWeight = vec4(0.0);
    outEmissive = vec4(0.0);
    float slot = texelFetch(gEmissive, px, 0).a;
    if (slot < 0.5) return;  // not a specular pixel (the depth test keeps most of them out)
    outEmissive.a = 1.0;
    vec3 p = texelFetch(gPosition, px, 0).xyz;
    vec3 n = texelFetch(gNormal, px, 0).xyz;
    float sigma = 0.002 + 0.005 * distance(cameraPos.xyz, p);
    ivec2 own = px / 2, halfSize = textureSize(halfHits[0], 0);
    // The neighbouring blocks towards this pixel's side of its own block.
    ivec2 toward = ivec2((px.x & 1) == 1 ? 1 : -1, (px.y & 1) == 1 ? 1 : -1);
    ivec2 best = ivec2(-1);
    float bestScore = -1.0;
    for (int c = 0; c < 4; ++c) {
        ivec2 q = own + ivec2(c & 1, c >> 1) * toward;
        if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, halfSize))) continue;
        ivec2 rep = blockRepresentative(q);
        if (rep.x < 0 || abs(texelFetch(gEmissive, rep, 0).a - slot) > 0.5) continue;
        vec3 pr = texelFetch(gPosition, rep, 0).xyz;
        vec3 nr = texelFetch(gNormal, rep, 0).xyz;
        float plane = dot(n, pr - p) / sigma;
        float score = exp(-min(plane * plane, 30.0)) * pow(max(dot(n, nr), 0.0), 8.0) +
                      (c == 0 ? 1e-3 : 0.0);
        if (score > bestScore) {
            bestScore = score;
            best = q;
        }
    }
    if (best.x < 0) return;  // no block of this object around: no hit (as a pixel nothing lit)
    int first = mode == 0 ? 0 : 5;
    outPosition = texelFetch(halfHits[first], best, 0);
    outNormal = texelFetch(halfHits[first + 1], best, 0);
    outAlbedo = texelFetch(halfHits[first + 2], best, 0);
    outEmissive = vec4(texelFetch(halfHits[first + 3], best, 0).rgb, 1.0);
    outWeight = texelFetch(halfHits[first + 4], best, 0);
}
