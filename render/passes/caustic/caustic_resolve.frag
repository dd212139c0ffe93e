#version 450 core
#include "common.glsl"
#include "passes/caustic/caustic.glsl"
// Caustic radiance from the caustic buffer (fixed-point irradiance, caustic_splat.comp), routed
// by Eqs. 12-14 of Knecht 2013: L_rv gets every caustic; L_r only the photons whose light and
// specular object are real (their power is in layers 3-5) landing on a REAL receiver. The
// receiver reflects the irradiance diffusely (Lambert, base colour x (1 - metallic) / pi).
// Linear radiance, canvas size.
in vec2 uv;
layout(binding = kUnitResolveAccum) uniform usampler2DArray accum;
layout(binding = kUnitResolvePosition) uniform sampler2D gPosition;  // w = origin
layout(binding = kUnitResolveAlbedo) uniform sampler2D gAlbedo;      // rgb, a = metallic
layout(binding = kUnitResolveEmissive) uniform sampler2D gEmissive;  // a = specular slot + 1
uniform float invFixedScale;
layout(location = 0) out vec4 outRv;
layout(location = 1) out vec4 outR;
void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    outRv = vec4(0.0, 0.0, 0.0, 1.0);
    outR = vec4(0.0, 0.0, 0.0, 1.0);
    int origin = int(texelFetch(gPosition, px, 0).w + 0.5);
    if (origin == ORIGIN_NONE || texelFetch(gEmissive, px, 0).a > 0.5) return;
    vec4 A = texelFetch(gAlbedo, px, 0);
    vec3 eRv = vec3(texelFetch(accum, ivec3(px, 0), 0).r, texelFetch(accum, ivec3(px, 1), 0).r,
                    texelFetch(accum, ivec3(px, 2), 0).r) * invFixedScale;
    vec3 eR = vec3(texelFetch(accum, ivec3(px, 3), 0).r, texelFetch(accum, ivec3(px, 4), 0).r,
                   texelFetch(accum, ivec3(px, 5), 0).r) * invFixedScale;
    causticRadiance(eRv, eR, A.rgb, A.a, origin == ORIGIN_REAL, outRv.rgb, outR.rgb);
}
