#version 450 core
#include "common.glsl"
#include "temporal.glsl"
#include "passes/caustic/caustic.glsl"
// Caustic radiance from the caustic buffer (fixed-point irradiance, caustic_splat.comp), routed
// by Eqs. 12-14 of Knecht 2013: L_rv gets every caustic; L_r only the photons whose light and
// specular object are real (their power is in layers 3-5) landing on a REAL receiver. The
// receiver reflects the irradiance diffusely (Lambert, base colour x (1 - metallic) / pi).
// Before the routing, the irradiance is smoothed over time (Knecht 2013 end of Sec. 4.2): a
// tracked camera jitters every frame, which moves the photon footprints over the pixels. Last
// frame's irradiance is reprojected by the receiver's world position and blended in where it is
// the same surface (temporal.glsl); irradiance, not radiance, is kept, so that a textured
// receiver's albedo is never blurred by the bilinear lookup. Linear radiance, canvas size.
// Only the tiles the caustic can reach are drawn (CausticTiles.h: the photons' tiles and where
// last frame's history can pass); every other pixel keeps the cleared 0, in the light and in the
// history alike.
layout(binding = kUnitResolveAccum) uniform usampler2DArray accum;
layout(binding = kUnitResolvePosition) uniform sampler2D gPosition;  // w = origin
layout(binding = kUnitResolveAlbedo) uniform sampler2D gAlbedo;      // rgb, a = metallic
layout(binding = kUnitResolveEmissive) uniform sampler2D gEmissive;  // a = specular slot + 1
// Last frame's smoothed irradiance (W/m^2) for L_rv / L_r, a = camera distance (m), 0: none.
layout(binding = kUnitResolveHistoryRv) uniform sampler2D historyRv;
layout(binding = kUnitResolveHistoryR) uniform sampler2D historyR;
// Per tile (kCausticTileSize), for the next frame's choice of tiles (CausticTiles.h): 1 where
// the history written here is not 0, and the nearest and farthest camera distance of the pixels
// resolved (floatBitsToUint of a positive float: its order is the float's).
layout(r32ui, binding = kImageCausticHistoryTiles) uniform writeonly uimage2D historyTilesOut;
layout(r32ui, binding = kImageCausticHistoryNear) uniform uimage2D historyNearOut;
layout(r32ui, binding = kImageCausticHistoryFar) uniform uimage2D historyFarOut;
uniform float invFixedScale;
uniform float historyWeight;  // the history's share; 0: none this frame (TemporalHistory)
layout(location = 0) out vec4 outRv;
layout(location = 1) out vec4 outR;
layout(location = 2) out vec4 outHistoryRv;  // the next frame's history
layout(location = 3) out vec4 outHistoryR;
void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    outRv = vec4(0.0, 0.0, 0.0, 1.0);
    outR = vec4(0.0, 0.0, 0.0, 1.0);
    outHistoryRv = vec4(0.0);
    outHistoryR = vec4(0.0);
    vec4 P = texelFetch(gPosition, px, 0);
    int origin = int(P.w + 0.5);
    if (origin == ORIGIN_NONE || texelFetch(gEmissive, px, 0).a > 0.5) return;
    vec4 A = texelFetch(gAlbedo, px, 0);
    vec3 eRv = vec3(texelFetch(accum, ivec3(px, 0), 0).r, texelFetch(accum, ivec3(px, 1), 0).r,
                    texelFetch(accum, ivec3(px, 2), 0).r) * invFixedScale;
    vec3 eR = vec3(texelFetch(accum, ivec3(px, 3), 0).r, texelFetch(accum, ivec3(px, 4), 0).r,
                   texelFetch(accum, ivec3(px, 5), 0).r) * invFixedScale;
    vec2 puv;
    if (historyWeight > 0.0 && reprojectToPreviousFrame(P.xyz, puv)) {
        vec4 hRv = texture(historyRv, puv);
        vec4 hR = texture(historyR, puv);
        // The surface test on the camera distance of the texels that hold one: a texel the
        // resolve skipped (no caustic: irradiance 0) is cleared to distance 0 as well, and takes
        // part in the lookup as the 0 it stands for instead of failing the test.
        vec2 f = fract(puv * canvas.xy - 0.5);
        vec4 w = vec4((1.0 - f.x) * f.y, f.x * f.y, f.x * (1.0 - f.y), (1.0 - f.x) * (1.0 - f.y));
        vec4 a = textureGather(historyRv, puv, 3);
        vec4 held = vec4(greaterThan(a, vec4(0.0)));
        float heldWeight = dot(w, held);
        float storedDistance = heldWeight > 0.0 ? dot(w, a) / heldWeight : 0.0;
        if (historyIsSameSurface(storedDistance, P.xyz) && allFinite(hRv.rgb) &&
            allFinite(hR.rgb)) {
            eRv = mix(eRv, max(hRv.rgb, vec3(0.0)), historyWeight);
            eR = mix(eR, max(hR.rgb, vec3(0.0)), historyWeight);
        }
    }
    float camDist = length(P.xyz - cameraPos.xyz);
    outHistoryRv = vec4(eRv, camDist);
    outHistoryR = vec4(eR, camDist);
    const ivec2 tile = px / kCausticTileSize;
    if (any(greaterThan(max(eRv, eR), vec3(0.0)))) imageStore(historyTilesOut, tile, uvec4(1u));
    imageAtomicMin(historyNearOut, tile, floatBitsToUint(camDist));
    imageAtomicMax(historyFarOut, tile, floatBitsToUint(camDist));
    causticRadiance(eRv, eR, A.rgb, A.a, origin == ORIGIN_REAL, outRv.rgb, outR.rgb);
}
