#version 450 core
#include "common.glsl"
#include "lighting.glsl"
#include "passes/translucency/translucency.glsl"
// Direct light, environment light and emission, routed into the two GI solutions
// (docs/realtime-renderer.md, "Real and virtual: routing"; Knecht 2010's decision flags):
//   L_rv: every light, visibility against all occluders;
//   L_r : only if the light and p are real, visibility against real occluders only.
// The environment map is real (captured) unless the scene says otherwise; it is not shadowed.
in vec2 uv;
layout(binding = kUnitDirectPosition) uniform sampler2D gPosition;  // xyz world, w = origin
layout(binding = kUnitDirectNormal) uniform sampler2D gNormal;
layout(binding = kUnitDirectAlbedo) uniform sampler2D gAlbedo;
layout(binding = kUnitDirectEmissive) uniform sampler2D gEmissive;
layout(binding = kUnitDirectShadowAll) uniform sampler2DArray shadowAll;
layout(binding = kUnitDirectShadowReal) uniform sampler2DArray shadowReal;
#ifdef MIRAGE_GLASS_SHADOWS
layout(binding = kUnitDirectGlassAll) uniform sampler2DArray glassAll;
layout(binding = kUnitDirectGlassReal) uniform sampler2DArray glassReal;
#endif
// The translucency pass's radiance leaving each surface voxel of the translucent objects
// (before the exit F_t): per object its S vec4 for L_rv, then its S for L_r (translucency.glsl).
// Read only when translucentOn. Scenes without a translucent object compile without this code
// (MIRAGE_NO_TRANSLUCENCY): llvmpipe runs an untaken branch's buffer reads for every pixel.
layout(std430, binding = kBindingTranslucentRadiance) readonly buffer TranslucentRadianceBlock {
    vec4 translucentL[];
};
uniform int translucentOn;  // 1: the translucency pass ran this frame
// 1: a translucent pixel also shows what lies behind its object through the chord the camera ray
// crosses (TranslucencyOptions::seeThrough): the share F_t^2 e^{-tau} of the footage behind,
// passed to the composite in LRv.a (as VnmShading's renderVnm adds the background).
uniform int translucentSeeThrough;
// Variant MIRAGE_WITH_INDIRECT (frames with VPL light): the outputs are the GI solutions, direct
// plus the filtered indirect light upsampled to the pixel (gi_upsample.glsl); MIRAGE_KEEP_DIRECT
// also writes the direct light alone (RendererOptions::keepDirectLight).
#ifdef MIRAGE_WITH_INDIRECT
#include "passes/direct/gi_upsample.glsl"
#endif
layout(location = 0) out vec4 outRv;  // linear radiance; a = the pixel's origin (ORIGIN_*)
layout(location = 1) out vec4 outR;
#ifdef MIRAGE_KEEP_DIRECT
layout(location = 2) out vec4 outDirectRv;
layout(location = 3) out vec4 outDirectR;
#endif

// Direct, environment and emitted light at the G-buffer pixel px (surface point P.xyz, origin
// real or virtual), both GI solutions; seeThrough = the share of what lies behind it that the
// pixel lets through (a translucent object's, else 0).
void directLight(ivec2 px, vec4 P, vec4 N, bool pReal, out vec3 rv, out vec3 r,
                 out float seeThrough) {
    vec3 p = P.xyz;
    vec3 n = N.xyz;
    vec4 A = texelFetch(gAlbedo, px, 0);
    vec3 v = normalize(cameraPos.xyz - p);
    rv = vec3(0.0);
    r = vec3(0.0);
    seeThrough = 0.0;
    vec4 Em = texelFetch(gEmissive, px, 0);
    // A translucent pixel (gEmissive.a = -IOR <= -1) takes the light scattered through its object (the
    // one whose map has the nearest surface voxel) to that surface voxel, times F_t towards the
    // camera (VnmShading::scattered), instead of the surface BRDF: L_rv from all lights, L_r from
    // real lights with the real-only shadow maps (and nothing on a virtual object, as for any
    // virtual pixel). An object beyond the ones with a map has no voxel: shaded as a surface.
#ifndef MIRAGE_NO_TRANSLUCENCY  // the variant for scenes without translucent objects
    int object, voxel;
    if (translucentOn == 1 && Em.a < -0.5 && translucentVoxelAt(p, object, voxel)) {
        TranslucentObjectGpu obj = translucentObjects[object];
        int base = 2 * obj.offsets.y;  // the object's slice: S for L_rv, then S for L_r
        float Ft = boundaryTransmittance(obj.params.x, abs(dot(n, v)));
        // The smooth lookup blends the voxels around p (no stripes where the grid cuts a face
        // at an angle); without it, or with no voxel centre near, the nearest voxel alone.
        int voxels[27];
        float weights[27];
        int count = obj.params.z > 0.5 ? translucentWeights(object, p, voxels, weights) : 0;
        if (count == 0) {
            count = 1;
            voxels[0] = voxel;
            weights[0] = 1.0;
        }
        for (int j = 0; j < count; ++j) {
            rv += weights[j] * translucentL[base + voxels[j]].rgb;
            if (pReal) r += weights[j] * translucentL[base + obj.gridDims.w + voxels[j]].rgb;
        }
        rv *= Ft;
        r *= Ft;
        if (translucentSeeThrough == 1) {
            // The background through the chord, both boundaries' F_t taken at the entry's
            // angle (the exit's normal is not at hand here).
            float a = translucentChordTransmittance(object, voxel, p, -v);
            seeThrough = Ft * Ft * a;
        }
        rv += Em.rgb;
        if (pReal) r += Em.rgb;
        return;
    }
#endif
    setShadowPixelFootprint(p, n);  // the focused shadow maps filter over the pixel
    for (int li = 0; li < lightCount; ++li) {
        vec3 wi, E;
        incidentLight(li, p, wi, E);
        float NdotL = dot(n, wi);
        if (NdotL <= 0.0) continue;
        vec3 c = brdfCos(n, v, wi, A.rgb, A.a, N.w) * E;
        vec3 visAll, visReal;
#ifdef MIRAGE_GLASS_SHADOWS
        lightVisibility(shadowAll, shadowReal, glassAll, glassReal, li, p, NdotL, visAll, visReal);
#else
        lightVisibility(shadowAll, shadowReal, li, p, NdotL, visAll, visReal);
#endif
        rv += c * visAll;  // all occluders
        if (lights[li].isReal == 1 && pReal) r += c * visReal;  // real occluders only
    }
    if (envOrigin != 0) {
        vec3 env = A.rgb * (1.0 - A.a) / PI * shIrradiance(n);
        rv += env;
        if (envOrigin == ORIGIN_REAL && pReal) r += env;
    }
    vec3 e = Em.rgb;
    rv += e;
    if (pReal) r += e;
}

#ifdef MIRAGE_ROUGH_HIGHLIGHT
#include "passes/specular/specular.glsl"
#include "passes/direct/rough_transmission.glsl"
// Variant for the pixels of rough mirrors, metals and glass (roughness above the mirror
// threshold 0.05; the specular passes light them along the mirror / refracted ray, which never
// meets a punctual light): the punctual lights' GGX highlight alone, F0 the metal's base colour or
// 0.04 for glass, and on rough glass the lights' light it lets through (rough_transmission.glsl),
// routed as the direct light (docs/realtime-renderer.md, "Real and virtual:
// routing"). The composite adds it to the specular pixel's L'_rv / L'_r after the fuzzy / rough
// filters (it is the lobe already).
// Other pixels are left as the main draw wrote them. LR.a = 2 marks a highlight pixel.
const float kRoughHighlightThreshold = 0.05;
void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 P = texelFetch(gPosition, px, 0);
    int origin = int(P.w + 0.5);
    vec4 N = texelFetch(gNormal, px, 0);
    if (origin == ORIGIN_NONE || texelFetch(gEmissive, px, 0).a < 0.5 ||
        !(N.w > kRoughHighlightThreshold))
        discard;
    vec4 A = texelFetch(gAlbedo, px, 0);
    vec3 v = normalize(cameraPos.xyz - P.xyz);
    vec3 F0 = mix(vec3(0.04), A.rgb, clamp(A.a, 0.0, 1.0));
    bool pReal = origin == ORIGIN_REAL;
    vec3 rv = vec3(0.0), r = vec3(0.0);
    setShadowPixelFootprint(P.xyz, N.xyz);
    for (int li = 0; li < lightCount; ++li) {
        vec3 wi, E;
        incidentLight(li, P.xyz, wi, E);
        float NdotL = dot(N.xyz, wi);
        if (NdotL <= 0.0) continue;
        vec3 F;
        vec3 c = ggxSpecularCos(N.xyz, v, wi, F0, N.w, F) * E;
        vec3 visAll, visReal;
#ifdef MIRAGE_GLASS_SHADOWS
        lightVisibility(shadowAll, shadowReal, glassAll, glassReal, li, P.xyz, NdotL, visAll,
                        visReal);
#else
        lightVisibility(shadowAll, shadowReal, li, P.xyz, NdotL, visAll, visReal);
#endif
        rv += c * visAll;
        if (lights[li].isReal == 1 && pReal) r += c * visReal;
    }
    // Rough glass also lets the lights through (rough_transmission.glsl).
    roughGlassTransmission(px, P.xyz, N.xyz, N.w, pReal, rv, r);
    rv = allFinite(rv) ? rv : vec3(0.0);
    r = allFinite(r) ? r : vec3(0.0);
    outRv = vec4(rv, float(origin));
    outR = vec4(r, 2.0);
#ifdef MIRAGE_KEEP_DIRECT
    outDirectRv = vec4(rv, 1.0);
    outDirectR = vec4(r, 1.0);
#endif
}
#else
void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 P = texelFetch(gPosition, px, 0);
    int origin = int(P.w + 0.5);
    vec3 rv = vec3(0.0), r = vec3(0.0), iRv = vec3(0.0), iR = vec3(0.0);
    float seeThrough = 0.0;
    if (origin != ORIGIN_NONE) {
        vec4 N = texelFetch(gNormal, px, 0);
        directLight(px, P, N, origin == ORIGIN_REAL, rv, r, seeThrough);
        rv = allFinite(rv) ? rv : vec3(0.0);
        r = allFinite(r) ? r : vec3(0.0);
#ifdef MIRAGE_WITH_INDIRECT
        upsampleIndirect(px, textureSize(gPosition, 0), P.xyz, N.xyz, iRv, iR);
#endif
    }
    // a: the origin, for the composite's diffuse variant, + the see-through share (common.glsl)
    outRv = vec4(rv + iRv, float(origin) + kSeeThroughScale * seeThrough);
    outR = vec4(r + iR, 1.0);
#ifdef MIRAGE_KEEP_DIRECT
    outDirectRv = vec4(rv, 1.0);
    outDirectR = vec4(r, 1.0);
#endif
}
#endif
