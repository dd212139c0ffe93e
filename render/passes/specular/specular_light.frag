#version 450 core
#include "common.glsl"
#include "temporal.glsl"
#include "lighting.glsl"
#include "passes/specular/specular.glsl"
#include "passes/caustic/caustic.glsl"
// Lighting of the reflected / refracted ray hits (GBuf_refl, GBuf_refr) by every light (shadow
// maps), the environment (SH irradiance) and the VPLs (imperfect shadow maps), routed by
// Knecht 2013 Eqs. 3-5:
//   L'_rv = sum_ls  eta1 L_refl(ls) + eta2 T L_refr(ls)                       (Eq. 3)
//   L'_r  = sum_ls  eta1 L_refl(ls) real(ls, p_refl) + eta2 T L_refr(ls) real(ls, p_refr) (Eq. 4)
//   real(ls, p) = r(ls) and r(p)                                              (Eq. 5)
// with visibility against all occluders for L'_rv and real occluders only for L'_r
// (docs/realtime-renderer.md, "Real and virtual: routing"). The Fresnel / transmittance weights
// (eta1, eta2 T) are pre-multiplied (Sec. 5.1). A ray that hit nothing modelled writes the
// weighted environment radiance into L_env instead (Sec. 4.1.3); L'_rv and L'_r stay untouched
// there. Linear radiance throughout.
// Variant MIRAGE_CAUSTIC_GATHER (frames with a world-space photon grid): each hit also gathers
// the caustic photons around it (caustic.glsl gatherCaustic), routed as the camera's caustic.
// Variant MIRAGE_SPECULAR_HALF (RendererOptions::specularHalfResolution): drawn at half the
// canvas size per axis; half pixel q shades ONE specular canvas pixel of its 2x2 block (the first
// in row order: its representative) and writes each hit's radiance unweighted, without emission
// and divided by (albedo + kSpecularDemodulationFloor), so that specular_resolve.frag can
// upsample it by hit geometry and put back the full-resolution Fresnel weight, albedo, emission
// and environment. The VPL interleaving tiles then cover 2x2 half pixels (4x4 canvas pixels).
// Variant MIRAGE_REFLECTION_ONLY: for the rectangles of mirrors and metals alone (no glass meets
// them: every refraction weight is 0), the reflected hit only (llvmpipe pays for the refracted
// hit's code even where its weight is 0).
// Then L'_rv, L'_r and the reflection's share are smoothed over time (Knecht 2013 end of Sec.
// 4.2): last frame's values, reprojected by the specular surface's world position, are blended
// in where the pixel is the same surface (temporal.glsl) AND both of its rays hit where they hit
// then (a reflection moves over the mirror differently from the mirror itself: under camera
// motion the hits move and the history is rejected rather than smeared; under tracking noise
// they stay within a few millimetres and it is used).
#ifdef MIRAGE_REFLECTION_ONLY
const int kComponents = 1;
#else
const int kComponents = 2;
#endif
in vec2 uv;
layout(binding = kUnitSpecLightVpls) uniform samplerBuffer vplTexels;  // GpuVpl[] (vplAt)
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
layout(binding = kUnitSpecLightShadowAll) uniform sampler2DArray shadowAll;
layout(binding = kUnitSpecLightShadowReal) uniform sampler2DArray shadowReal;
#ifdef MIRAGE_GLASS_SHADOWS
layout(binding = kUnitSpecLightGlassAll) uniform sampler2DArray glassAll;
layout(binding = kUnitSpecLightGlassReal) uniform sampler2DArray glassReal;
#endif
layout(binding = kUnitSpecLightIsmAll) uniform usampler2D ismAll;
layout(binding = kUnitSpecLightIsmReal) uniform usampler2D ismReal;
layout(binding = kUnitSpecLightPosition) uniform sampler2D gPosition;  // primary G-buffer
layout(binding = kUnitEnvironmentMap) uniform sampler2D envMap;
uniform int useVpls;    // 1 when VPLs (and their ISMs) exist this frame
uniform int vplStride;  // interleaving: pixel p sums VPLs g, g + stride, ... (g from p), x stride
#ifdef MIRAGE_SPECULAR_HALF
// Hit radiance of the block's representative (rgb, see above). outReflRv.a = 1 + the
// representative's index in the 2x2 block (x + 2 y), 0 where the block has no specular pixel.
layout(location = 0) out vec4 outReflRv;  // reflected hit, L_rv
layout(location = 1) out vec4 outReflR;   // reflected hit, L_r
layout(location = 2) out vec4 outRefrRv;  // refracted hit, L_rv
layout(location = 3) out vec4 outRefrR;   // refracted hit, L_r
#else
uniform float historyWeight;  // the history's share; 0: none this frame (TemporalHistory)
// Temporal reuse (SpecularOptions::refreshInterval): 1 shades every specular pixel. N = 2 or 4:
// only the 8x8-pixel tiles of this frame's phase (of N, in a 2x2-tile pattern) are shaded; a pixel
// of the other tiles takes its history as it is where the history holds this frame's hits (the
// light at a hit does not depend on where it is seen from; the Fresnel weight changes little over
// the frames a tile waits) and is shaded where it does not (a disocclusion, a hit that moved
// more than 0.5 mm: sameHitForReuse). Tiles of 8x8 so that a SIMD group (a GPU's warp, llvmpipe's
// 4x4 block) is shaded or not as a whole: a GPU then skips the shading; llvmpipe runs its
// straight-line code anyway and skips only its loops (lights, VPLs, photons) once no lane is in
// them.
uniform int refreshInterval;  // 1, 2 or 4; 1 also where the history cannot be used this frame
uniform int refreshPhase;     // this frame's tiles: frame index mod refreshInterval
// Last frame's smoothed L'_rv (a = the specular surface's camera distance, m; 0: no specular
// pixel), L'_r and the reflection's share of L'_r, and the hits they were lit at: the reflected
// ray's in historyHits.xyz, the refracted ray's in (historyHits.w, historyR.a, historyRRefl.a)
// (world, m; kNoHit where a ray hit nothing).
layout(binding = kUnitSpecLightHistoryRv) uniform sampler2D historyRv;
layout(binding = kUnitSpecLightHistoryR) uniform sampler2D historyR;
layout(binding = kUnitSpecLightHistoryRRefl) uniform sampler2D historyRRefl;
layout(binding = kUnitSpecLightHistoryHits) uniform sampler2D historyHits;
// This frame's smoothed values are the next frame's history: each output is both (the alpha
// channels carry what the history test compares, as above).
layout(location = 0) out vec4 outRv;     // L'_rv
layout(location = 1) out vec4 outR;      // L'_r
layout(location = 2) out vec4 outRRefl;  // the reflection's share of L'_r (for Eq. 9, see
                                         // composite.frag)
layout(location = 3) out vec4 outEnv;    // L_env; a = 1 on specular pixels
layout(location = 4) out vec4 outHits;   // the hits, as historyHits

const float kNoHit = 1e6;  // the hit of a ray that hit nothing modelled (or was not traced)

// The value of x at the other pixel of this pixel's 2x2 quad in x / y (fine derivatives are the
// exact differences within a quad; llvmpipe shades whole quads).
vec4 quadSwapX(vec4 x) { return x + ((int(gl_FragCoord.x) & 1) == 0 ? 1.0 : -1.0) * dFdxFine(x); }
vec4 quadSwapY(vec4 x) { return x + ((int(gl_FragCoord.y) & 1) == 0 ? 1.0 : -1.0) * dFdyFine(x); }

// The VPL irradiance of one ray's hit averaged over the pixel's 2x2 quad: a quad holds four VPL
// subsets (the interleaving tile is 2x2 or 4x4), so the average sums 4x the VPLs of one pixel and
// the tile's pattern is a quarter as strong. A neighbour counts where it has a hit of this ray
// (valid = 1) of the same origin (real / virtual: a virtual hit's L_r must stay without real
// light) near this pixel's: within 1 % of the path from the camera + 3 mm, weight falling off
// with the distance, so the light of one surface does not leak onto another across an edge.
// Call in uniform control flow (derivatives). irr.w / irrR.w: valid (0 or 1).
void quadAverage(inout vec4 irrRv, inout vec4 irrR, vec3 hit, int origin, float pathLength) {
    vec4 h = vec4(hit, float(origin));
    vec4 sumRv = irrRv * irrRv.w, sumR = irrR * irrRv.w;
    float wsum = irrRv.w;
    for (int j = 0; j < 3; ++j) {
        vec4 nRv = j == 0 ? quadSwapX(irrRv) : j == 1 ? quadSwapY(irrRv) : quadSwapX(quadSwapY(irrRv));
        vec4 nR = j == 0 ? quadSwapX(irrR) : j == 1 ? quadSwapY(irrR) : quadSwapX(quadSwapY(irrR));
        vec4 nh = j == 0 ? quadSwapX(h) : j == 1 ? quadSwapY(h) : quadSwapX(quadSwapY(h));
        float t = distance(nh.xyz, hit) / (0.01 * pathLength + 0.003);
        float w = nRv.w > 0.5 && abs(nh.w - float(origin)) < 0.5 ? 1.0 / (1.0 + t * t) : 0.0;
        sumRv += w * nRv;
        sumR += w * nR;
        wsum += w;
    }
    if (irrRv.w > 0.5 && wsum > 0.0) {
        irrRv = vec4(sumRv.rgb / wsum, 1.0);
        irrR = vec4(sumR.rgb / wsum, 1.0);
    }
}

// A history hit may stand in for this frame's light without shading: the same hit within 0.5 mm
// (both rays hit nothing: both kNoHit). Stricter than sameHit, which only lets the history into
// a blend: taken as it is at sameHit's tolerance, the light of a reflected edge or texture a few
// millimetres away cost 0.6 dB over the influenced pixels on an orbiting camera (docs/specular.md).
bool sameHitForReuse(vec3 stored, vec3 current) {
    return distance(stored, current) < 0.0005;
}

// The tile of pixel px is shaded this frame (see refreshInterval).
bool tileRefreshedNow(ivec2 px) {
    if (refreshInterval <= 1) return true;
    ivec2 tile = px >> 3;
    // 2x2 tiles cover the phases of 4 in the order 0 3 / 2 1 (each phase's tiles spread evenly);
    // 2 phases take the diagonals of the same pattern.
    int order = (tile.x & 1) == 0 ? ((tile.y & 1) == 0 ? 0 : 2) : ((tile.y & 1) == 0 ? 3 : 1);
    return order % refreshInterval == refreshPhase;
}

// A history hit (world, m) is this frame's hit: both rays hit nothing, or both hit within
// 0.5 % of the path from the camera + 2 mm of each other (a few pixels' footprint at the hit;
// tracking noise moves a hit by about a millimetre, a moving camera by centimetres).
bool sameHit(vec3 stored, vec3 current, float pathLength) {
    return distance(stored, current) < 0.005 * pathLength + 0.002;
}
#endif

// Outgoing radiance of hit point x towards the specular surface (unit v), both GI solutions:
// lights, environment and emission in rv / r; the irradiance (W/m^2) from the interleaved VPL
// subset (x stride) in vplRv / vplR, which the caller turns into radiance (x albedo (1 -
// metallic) / pi), after averaging it over the quad in the full-resolution variant.
void shadeHit(vec3 x, bool xReal, vec3 n, vec3 v, vec3 albedo, float metallic, float roughness,
              vec3 emissive, int firstVpl, out vec3 rv, out vec3 r, out vec3 vplRv,
              out vec3 vplR) {
    rv = vec3(0.0);
    r = vec3(0.0);
    vplRv = vec3(0.0);
    vplR = vec3(0.0);
    for (int li = 0; li < lightCount; ++li) {
        vec3 wi, E;
        incidentLight(li, x, wi, E);
        float NdotL = dot(n, wi);
        if (NdotL <= 0.0) continue;
        vec3 c = brdfCos(n, v, wi, albedo, metallic, roughness) * E;
        vec3 visAll, visReal;
#ifdef MIRAGE_GLASS_SHADOWS
        lightVisibility(shadowAll, shadowReal, glassAll, glassReal, li, x, NdotL, visAll, visReal);
#else
        lightVisibility(shadowAll, shadowReal, li, x, NdotL, visAll, visReal);
#endif
        rv += c * visAll;  // all occluders
        if (lights[li].isReal == 1 && xReal) r += c * visReal;  // real occluders only
    }
    if (envOrigin != 0) {
        vec3 env = albedo * (1.0 - metallic) / PI * shIrradiance(n);
        rv += env;
        if (envOrigin == ORIGIN_REAL && xReal) r += env;
    }
    if (useVpls == 1) {
        float clamp2 = vplDistanceClamp * vplDistanceClamp;
        int stride = max(vplStride, 1);
        vec3 vrv = vec3(0.0), vr = vec3(0.0);
        for (int i = firstVpl; i < vplCount; i += stride) {
            GpuVpl V = vplAt(vplTexels, i);
            if (V.valid == 0) continue;
            vec3 d = x - V.position;
            float dist2 = dot(d, d);
            if (dist2 < 1e-10) continue;
            float dist = sqrt(dist2);
            vec3 w = d / dist;
            float cosQ = dot(V.normal, w), cosP = dot(n, -w);
            if (cosQ <= 0.0 || cosP <= 0.0) continue;
            vec3 c = V.flux / PI * cosQ * cosP / max(dist2, clamp2);
            float bias = 0.02 + 0.03 * dist;
            vec2 puv = paraboloidUv(V, w);
            if (dist - bias <= ismDistance(ismAll, i, puv)) vrv += c;
            if (V.isReal != 0 && xReal && dist - bias <= ismDistance(ismReal, i, puv))
                vr += c;
        }
        vplRv = vrv * float(stride);
        vplR = vr * float(stride);
    }
    rv += emissive;
    if (xReal) r += emissive;
}

#ifdef MIRAGE_SPECULAR_HALF
void main() {
    // The representative: the first specular canvas pixel of this half pixel's 2x2 block.
    ivec2 block = 2 * ivec2(gl_FragCoord.xy), size = textureSize(reflEmissive, 0);
    int rep = -1;
    for (int i = 3; i >= 0; --i) {
        ivec2 c = block + ivec2(i & 1, i >> 1);
        if (all(lessThan(c, size)) && texelFetch(reflEmissive, c, 0).a >= 0.5) rep = i;
    }
    ivec2 px = block + ivec2(max(rep, 0) & 1, max(rep, 0) >> 1);
#ifdef MIRAGE_CAUSTIC_GATHER
    // Footprints from the neighbouring half pixels' representatives (2 canvas pixels apart: the
    // kernel must cover the half-resolution sample spacing).
    vec3 pSpec = texelFetch(gPosition, px, 0).xyz;
    float toCamera = distance(cameraPos.xyz, pSpec);
    float footprint[2] = float[2](0.0, 0.0);
    for (int k = 0; k < kComponents; ++k) {
        vec3 h = (k == 0 ? texelFetch(reflPosition, px, 0) : texelFetch(refrPosition, px, 0)).xyz;
        vec3 nh = (k == 0 ? texelFetch(reflNormal, px, 0) : texelFetch(refrNormal, px, 0)).xyz;
        float cosHit = abs(dot(nh, normalize(pSpec - h + vec3(0.0, 0.0, 1e-9))));
        footprint[k] = gatherFootprint(dFdx(h), dFdy(h), toCamera + distance(pSpec, h), cosHit);
    }
#endif
    outReflRv = vec4(0.0);
    outReflR = vec4(0.0);
    outRefrRv = vec4(0.0);
    outRefrR = vec4(0.0);
    if (rep < 0) return;  // no specular pixel in the block
    vec3 hitRv[2] = vec3[2](vec3(0.0), vec3(0.0)), hitR[2] = vec3[2](vec3(0.0), vec3(0.0));
    for (int k = 0; k < kComponents; ++k) {
        hitRv[k] = vec3(0.0);
        hitR[k] = vec3(0.0);
        vec4 P = k == 0 ? texelFetch(reflPosition, px, 0) : texelFetch(refrPosition, px, 0);
        vec3 w = (k == 0 ? texelFetch(reflWeight, px, 0) : texelFetch(refrWeight, px, 0)).rgb;
        int origin = int(P.w + 0.5);
        if (all(lessThanEqual(w, vec3(0.0))) || origin == ORIGIN_NONE) continue;
        vec4 N = k == 0 ? texelFetch(reflNormal, px, 0) : texelFetch(refrNormal, px, 0);
        vec4 A = k == 0 ? texelFetch(reflAlbedo, px, 0) : texelFetch(refrAlbedo, px, 0);
        vec3 v = normalize(texelFetch(gPosition, px, 0).xyz - P.xyz);
        if (!allFinite(v)) v = N.xyz;
        int st = max(vplStride, 1), side = st >= 16 ? 4 : (st >= 4 ? 2 : 1);
        ivec2 q = ivec2(gl_FragCoord.xy);
        int firstVpl = (q.x % side + side * (q.y % side)) % st;
        vec3 hrv, hr, vrv, vr;
        shadeHit(P.xyz, origin == ORIGIN_REAL, N.xyz, v, A.rgb, A.a, N.w, vec3(0.0), firstVpl,
                 hrv, hr, vrv, vr);
        hrv += A.rgb * (1.0 - A.a) / PI * vrv;
        hr += A.rgb * (1.0 - A.a) / PI * vr;
#ifdef MIRAGE_CAUSTIC_GATHER
        vec3 eRv, eR, crv, cr;
        gatherCaustic(P.xyz, N.xyz, footprint[k], eRv, eR);
        causticRadiance(eRv, eR, A.rgb, A.a, origin == ORIGIN_REAL, crv, cr);
        hrv += crv;
        hr += cr;
#endif
        vec3 demodulate = 1.0 / (A.rgb + kSpecularDemodulationFloor);
        hitRv[k] = allFinite(hrv) ? hrv * demodulate : vec3(0.0);
        hitR[k] = allFinite(hr) ? hr * demodulate : vec3(0.0);
    }
    outReflRv = vec4(hitRv[0], float(1 + rep));
    outReflR = vec4(hitR[0], 1.0);
    outRefrRv = vec4(hitRv[1], 1.0);
    outRefrR = vec4(hitR[1], 1.0);
}
#else
void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
#ifdef MIRAGE_CAUSTIC_GATHER
    // The gather points' footprints, from the hits of the neighbouring pixels (derivatives:
    // before any branch) and, across silhouettes, from the path length and the hit's obliquity.
    vec3 pSpec = texelFetch(gPosition, px, 0).xyz;
    float toCamera = distance(cameraPos.xyz, pSpec);
    float footprint[2] = float[2](0.0, 0.0);
    for (int k = 0; k < kComponents; ++k) {
        vec3 h = (k == 0 ? texelFetch(reflPosition, px, 0) : texelFetch(refrPosition, px, 0)).xyz;
        vec3 nh = (k == 0 ? texelFetch(reflNormal, px, 0) : texelFetch(refrNormal, px, 0)).xyz;
        float cosHit = abs(dot(nh, normalize(pSpec - h + vec3(0.0, 0.0, 1e-9))));
        footprint[k] = gatherFootprint(dFdx(h), dFdy(h), toCamera + distance(pSpec, h), cosHit);
    }
#endif
    outRv = vec4(0.0);
    outR = vec4(0.0);
    outRRefl = vec4(0.0);
    outEnv = vec4(0.0);
    outHits = vec4(0.0);
    // No early return before the quad decisions below: their derivatives need every lane's values.
    bool specularPixel = texelFetch(reflEmissive, px, 0).a >= 0.5;
    vec3 surface = texelFetch(gPosition, px, 0).xyz;
    float toSurface = distance(surface, cameraPos.xyz);
    // This frame's hits first (per ray, world, m): the history test needs them before the shading.
    vec3 hit[2] = vec3[2](vec3(kNoHit), vec3(kNoHit));
    for (int k = 0; k < kComponents && specularPixel; ++k) {
        vec4 P = k == 0 ? texelFetch(reflPosition, px, 0) : texelFetch(refrPosition, px, 0);
        vec3 w = (k == 0 ? texelFetch(reflWeight, px, 0) : texelFetch(refrWeight, px, 0)).rgb;
        if (!all(lessThanEqual(w, vec3(0.0))) && int(P.w + 0.5) != ORIGIN_NONE) hit[k] = P.xyz;
    }
    // Last frame's smoothed values at this pixel's surface; they hold where the surface and both
    // rays' hits are this frame's.
    vec4 hRv = vec4(0.0), hR = vec4(0.0), hRRefl = vec4(0.0);
    bool historyHolds = false, reuseHolds = false;
    vec2 puv;
    if (specularPixel && (historyWeight > 0.0 || refreshInterval > 1) &&
        reprojectToPreviousFrame(surface, puv)) {
        hRv = texture(historyRv, puv);
        hR = texture(historyR, puv);
        hRRefl = texture(historyRRefl, puv);
        vec4 hHits = texture(historyHits, puv);
        historyHolds = historyIsSameSurface(hRv.a, surface) &&
                       sameHit(hHits.xyz, hit[0], toSurface + distance(surface, hit[0])) &&
                       sameHit(vec3(hHits.w, hR.a, hRRefl.a), hit[1],
                               toSurface + distance(surface, hit[1])) &&
                       allFinite(hRv.rgb) && allFinite(hR.rgb) && allFinite(hRRefl.rgb);
        reuseHolds = historyHolds && sameHitForReuse(hHits.xyz, hit[0]) &&
                     sameHitForReuse(vec3(hHits.w, hR.a, hRRefl.a), hit[1]);
    }
    // Shaded unless its tile waits this frame and the history holds, decided per 2x2 quad so that
    // the quad average's derivatives see all four lanes shaded or none.
    vec4 need = vec4(specularPixel && !(reuseHolds && !tileRefreshedNow(px)) ? 1.0 : 0.0);
    bool shade = max(max(need.x, quadSwapX(need).x),
                     max(quadSwapY(need).x, quadSwapX(quadSwapY(need)).x)) > 0.5;
    vec3 rv = vec3(0.0), r = vec3(0.0), rRefl = vec3(0.0), env = vec3(0.0);
    // Per ray: the VPL irradiance at its hit (w: 1 if the ray has one), and what turns it into
    // this pixel's radiance (Fresnel weight x albedo (1 - metallic) / pi).
    vec4 vplRv[2] = vec4[2](vec4(0.0), vec4(0.0)), vplR[2] = vec4[2](vec4(0.0), vec4(0.0));
    vec3 vplToRadiance[2] = vec3[2](vec3(0.0), vec3(0.0));
    int hitOrigin[2] = int[2](ORIGIN_NONE, ORIGIN_NONE);
    for (int k = 0; k < kComponents && specularPixel; ++k) {
        vec4 P = k == 0 ? texelFetch(reflPosition, px, 0) : texelFetch(refrPosition, px, 0);
        vec3 w = (k == 0 ? texelFetch(reflWeight, px, 0) : texelFetch(refrWeight, px, 0)).rgb;
        if (all(lessThanEqual(w, vec3(0.0)))) continue;
        int origin = int(P.w + 0.5);
        if (origin == ORIGIN_NONE) {
            if (dot(P.xyz, P.xyz) > 0.25) env += w * environmentRadiance(envMap, P.xyz);
            continue;
        }
        if (!shade) continue;  // the history's light is taken below
        vec4 N = k == 0 ? texelFetch(reflNormal, px, 0) : texelFetch(refrNormal, px, 0);
        vec4 A = k == 0 ? texelFetch(reflAlbedo, px, 0) : texelFetch(refrAlbedo, px, 0);
        vec3 e = (k == 0 ? texelFetch(reflEmissive, px, 0) : texelFetch(refrEmissive, px, 0)).rgb;
        // Viewed from the specular surface point p (for the refracted ray the exit point lies
        // on the same object; its glossy highlights are approximate).
        vec3 v = normalize(surface - P.xyz);
        if (!allFinite(v)) v = N.xyz;
        vec3 hrv, hr, irrRv, irrR;
        // Interleaved VPL subsets: a 2x2 (stride 4) or 4x4 (16) pixel tile covers every VPL.
        int st = max(vplStride, 1), side = st >= 16 ? 4 : (st >= 4 ? 2 : 1);
        int firstVpl = (px.x % side + side * (px.y % side)) % st;
        shadeHit(P.xyz, origin == ORIGIN_REAL, N.xyz, v, A.rgb, A.a, N.w, e, firstVpl, hrv, hr,
                 irrRv, irrR);
        bool finiteIrr = allFinite(irrRv) && allFinite(irrR);
        vplRv[k] = vec4(finiteIrr ? irrRv : vec3(0.0), 1.0);
        vplR[k] = vec4(finiteIrr ? irrR : vec3(0.0), 1.0);
        vplToRadiance[k] = w * A.rgb * (1.0 - A.a) / PI;
        hitOrigin[k] = origin;
#ifdef MIRAGE_CAUSTIC_GATHER
        vec3 eRv, eR, crv, cr;
        gatherCaustic(P.xyz, N.xyz, footprint[k], eRv, eR);
        causticRadiance(eRv, eR, A.rgb, A.a, origin == ORIGIN_REAL, crv, cr);
        hrv += crv;
        hr += cr;
#endif
        rv += w * hrv;
        r += w * hr;
        if (k == 0) rRefl = w * hr;
    }
    if (shade) {  // the same in all lanes of the quad
        for (int k = 0; k < kComponents; ++k) {
            if (vplStride > 1)  // uniform: the quad's lanes all take it
                quadAverage(vplRv[k], vplR[k], hit[k], hitOrigin[k],
                            toSurface + distance(surface, hit[k]));
            rv += vplToRadiance[k] * vplRv[k].rgb;
            r += vplToRadiance[k] * vplR[k].rgb;
            if (k == 0) rRefl += vplToRadiance[k] * vplR[k].rgb;
        }
    }
    if (!specularPixel) return;
    if (!shade) {
        rv = max(hRv.rgb, vec3(0.0));
        r = max(hR.rgb, vec3(0.0));
        rRefl = max(hRRefl.rgb, vec3(0.0));
    } else {
        rv = allFinite(rv) ? rv : vec3(0.0);
        r = allFinite(r) ? r : vec3(0.0);
        rRefl = allFinite(rRefl) ? rRefl : vec3(0.0);
        if (historyWeight > 0.0 && historyHolds) {
            rv = mix(rv, max(hRv.rgb, vec3(0.0)), historyWeight);
            r = mix(r, max(hR.rgb, vec3(0.0)), historyWeight);
            rRefl = mix(rRefl, max(hRRefl.rgb, vec3(0.0)), historyWeight);
        }
    }
    outRv = vec4(rv, toSurface);
    outR = vec4(r, hit[1].y);
    outRRefl = vec4(rRefl, hit[1].z);
    outHits = vec4(hit[0], hit[1].x);
    outEnv = vec4(allFinite(env) ? env : vec3(0.0), 1.0);
}
#endif
