#version 450 core
#include "common.glsl"
#include "passes/specular/specular.glsl"
#include "passes/grain/footage_noise.glsl"
#include "passes/specular/second_exit.glsl"
// Differential rendering (Knecht 2013 Eqs. 1-2), one output pixel per camera pixel:
//   real or empty pixel:  L_final = CI + alpha * (L_rv - L_r),  alpha = CI / L_r per channel
//   virtual pixel:        L_final = L_rv (+ s CI on a translucent object: the share s of what
//                         lies behind it that it lets through, from LRv.a; direct.frag; + its
//                         boundary's reflection, boundaryReflection below)
// CI is the camera frame, sRGB-encoded 8-bit, linearised by the sRGB texture format (the camera
// response is taken to be the sRGB curve). L_* are scaled by `exposure` into camera units first.
// Guard where L_r is near 0 (a black surface, or light only the virtual light reaches): alpha
// fades to 1 below alphaFadeLr (the model's own radiometry is used) and is capped at alphaMax,
// and the result is clamped to >= 0 and finite. Lens distortion: the L buffers were rendered
// undistorted on the canvas; `remap` gives each camera pixel's canvas position (variant
// MIRAGE_IDENTITY_REMAP: no distortion and a canvas of the camera's size, position = pixel).
//
// Pixels showing a mirror or glass object (the G-buffer's specular slot) are composited by
// Knecht 2013 Eqs. 6-11 instead (docs/specular.md):
//   dL' = L'_rv - L'_r                                                        (Eq. 6)
//   all of p, p_refl, p_refr real:  L' = CI(p) + alpha' dL',  alpha' = CI(p) / (L'_r + L_env)
//   otherwise:                      L' = L_env + CI_bp + alpha' dL', alpha' = CI_bp / L'_r
//                                                                     (Eqs. 7, 8, 11)
//   CI_bp = eta1 CI_r(p_refl) + eta2 T CI_r(p_refr)                   (Eqs. 9, 10)
// CI(x) back-projects x into the camera image; it is valid when x is inside the frustum and
// the image and its camera distance matches the nearest REAL surface there within
// eps * distance + 5 mm (eps = RendererOptions::backProjectionEpsilon, default 2 %): the video
// only shows real surfaces, so an occluder (ray two of Fig. 2) rejects it, a virtual one does
// not. A virtual hit contributes CI_r = 0 (its light is all in dL'); a miss contributes 0 (its
// light is in L_env). Validation per component: where a real hit cannot be back-projected its
// rendered real radiance (its share of L'_r) stands in — when both fail this is exactly
// Eq. 9's "otherwise L'_r", and when p is virtual and p_refr is valid the refracted video is
// used whatever the reflection does (the seed's exception for virtual refractive objects),
// without taking an unvalidated colour for the reflection. alpha' is guarded like alpha.
//
// Rough metals and rough glass (render/passes/fuzzy): where the fuzzy pass marked the pixel,
// L'_rv, L'_r, its reflection share and L_env come from the filtered buffers, and CI_bp from the
// filtered, already resolved video term (each neighbour's eta CI_r(hit) per component, or its
// rendered real share where it could not be back-projected): the same equations on blurred
// lookups. Whether all of p, p_refl, p_refr are real is the pixel's own.
in vec2 uv;
layout(binding = kUnitCompositeCamera) uniform sampler2D cameraImage;  // sRGB8 texture: samples are linear
layout(binding = kUnitCompositeLRv) uniform sampler2D lRv;           // canvas, linear
layout(binding = kUnitCompositeLR) uniform sampler2D lR;
layout(binding = kUnitCompositeCausticRv) uniform sampler2D causticRv;  // caustic light (Eqs. 12-14)
layout(binding = kUnitCompositeCausticR) uniform sampler2D causticR;
layout(binding = kUnitCompositePosition) uniform sampler2D gPosition;     // canvas, w = origin
layout(binding = kUnitCompositeRemap) uniform sampler2D remap;         // camera size: canvas pixel (OpenCV conv.)
layout(binding = kUnitCompositeEmissive) uniform sampler2D gEmissive;     // canvas, a = specular slot + 1
layout(binding = kUnitCompositeReflPosition) uniform sampler2D reflPosition;  // GBuf_refl: xyz hit, w = origin
layout(binding = kUnitCompositeRefrPosition) uniform sampler2D refrPosition;  // GBuf_refr
layout(binding = kUnitCompositeReflWeight) uniform sampler2D reflWeight;    // eta1 (rgb)
layout(binding = kUnitCompositeRefrWeight) uniform sampler2D refrWeight;    // eta2 T (rgb)
layout(binding = kUnitCompositeSpecRv) uniform sampler2D specRv;       // L'_rv
layout(binding = kUnitCompositeSpecR) uniform sampler2D specR;        // L'_r
layout(binding = kUnitCompositeSpecRRefl) uniform sampler2D specRRefl;    // the reflection's share of L'_r
layout(binding = kUnitCompositeLenv) uniform sampler2D lEnv;         // L_env
layout(binding = kUnitCompositeRealSurfaces) uniform sampler2D realSurfaces; // nearest real surface, xyz world
layout(binding = kUnitCompositeCanvasToCamera) uniform sampler2D canvasToCamera;  // canvas: camera pixel of the ray
layout(binding = kUnitCompositeFuzzyRv) uniform sampler2D fuzzyRv;  // filtered L'_rv
layout(binding = kUnitCompositeFuzzyR) uniform sampler2D fuzzyR;    // filtered L'_r
layout(binding = kUnitCompositeFuzzyRRefl) uniform sampler2D fuzzyRRefl;
layout(binding = kUnitCompositeFuzzyLenv) uniform sampler2D fuzzyLenv;
layout(binding = kUnitCompositeFuzzyVideo) uniform sampler2D fuzzyVideo;  // rgb camera units, a = 1: fuzzy pixel
layout(binding = kUnitCompositeNormal) uniform sampler2D gNormal;  // canvas, xyz facing the camera
layout(binding = kUnitCompositeBackPosition) uniform sampler2D backPosition;  // w = slot + 1
layout(binding = kUnitCompositeBackNormal) uniform sampler2D backNormal;      // outward
layout(binding = kUnitCompositeEnvironment) uniform sampler2D envMap;         // equirectangular
uniform int fuzzyOn;         // 1 when the fuzzy pass ran this frame
uniform float depthEpsilon;  // relative camera-distance tolerance of the back-projection
uniform int showVirtual;     // 0: the footage unchanged (RendererOptions::showVirtual)
uniform int withCaustics;    // 1: a caustic pass ran (else causticRv / causticR are not read)
// 1: the footage seen in mirrors and glass is taken without its noise (footage_noise.glsl): the
// grain pass adds the noise of the pixel it is seen at (noiseVariance: the footage's levels).
uniform int denoiseFootage;
layout(location = 0) out vec4 outLinear;  // rgb linear; a = 0 empty, 0.5 real, 1 virtual
layout(location = 1) out vec4 outSrgb;    // written through GL_FRAMEBUFFER_SRGB: encoded sRGB8
// The part of outLinear that is footage, and the pixel's layer, for the motion blur
// (render/passes/motionblur): the footage is already blurred by the camera and must not be blurred
// again within its layer. rgb camera linear; a = 0: a real or empty pixel (rgb = CI), 1: a virtual
// pixel (rgb = 0), 2 + slot: a mirror / glass pixel (rgb = the back-projected video CI_bp).
// Attached only while the motion blur is on.
layout(location = 2) out vec4 outFootage;

// alpha for L = CI + alpha dL, guarded where the rendered real radiance is near 0.
vec3 guardedAlpha(vec3 ci, vec3 r) {
    vec3 t = smoothstep(vec3(0.0), vec3(alphaFadeLr), r);
    vec3 ratio = min(ci / max(r, vec3(1e-6)), vec3(alphaMax));
    return mix(vec3(1.0), ratio, t);
}

// The camera-image pixel that shows canvas pixel c (the lens map), false outside the image.
bool cameraPixelOfCanvas(ivec2 c, out ivec2 camPx) {
#ifdef MIRAGE_IDENTITY_REMAP
    vec2 q = vec2(c);
#else
    vec2 q = texture(canvasToCamera, (vec2(c) + 0.5) * canvas.zw).xy;
#endif
    ivec2 size = textureSize(cameraImage, 0);
    camPx = ivec2(floor(q + 0.5));
    return q.x > -0.5 && q.y > -0.5 && q.x < float(size.x) - 0.5 && q.y < float(size.y) - 0.5;
}

// The mirror reflection on a translucent object's boundary at canvas pixel cpi (gEmissive.a =
// -IOR): the share F_r = 1 - F_t (Fresnel, the smooth boundary the reference has) of the light
// arriving along the mirror ray r. What r meets is found by marching it over the G-buffer's
// nearest surfaces (screen space: the ray is taken to meet a surface where it passes behind it
// by less than the step; bisection then refines the point). A real surface gives what its pixel
// composites to (its footage plus alpha (L_rv - L_r), caustics included), a virtual one its
// L_rv; a ray that leaves the canvas or meets nothing within the march (0.68 m) sees the
// environment (its SH irradiance over pi: the environment as a matte surface facing r would
// average it). Returns the reflected radiance in camera units; `footageShare` the part of it
// that is footage.
#ifdef MIRAGE_TRANSLUCENT_REFLECTION
const int kReflectionSteps = 32;
const float kReflectionFirstM = 0.002;  // first step (metres)
const float kReflectionGrowth = 1.2;    // step growth: 0.002 * 1.2^32 = 0.68 m at the last
const int kReflectionBisections = 6;
vec3 boundaryReflection(ivec2 cpi, float ior, out vec3 footageShare) {
    footageShare = vec3(0.0);
    vec3 p = texelFetch(gPosition, cpi, 0).xyz;
    vec3 n = texelFetch(gNormal, cpi, 0).xyz;  // faces the camera (G-buffer convention)
    vec3 v = cameraPos.xyz - p;
    float vl = length(v);
    if (vl < 1e-6 || !allFinite(n) || dot(n, n) < 0.25) return vec3(0.0);
    v /= vl;
    n = normalize(n);
    float Fr = fresnelDielectric(clamp(dot(n, v), 1e-4, 1.0), max(ior, 1.0));
    if (!(Fr > 0.0)) return vec3(0.0);
    vec3 r = reflect(-v, n);
    vec3 o = p + n * (1e-4 + 1e-4 * vl);  // off the surface (metres)
    float t0 = 0.0, t = kReflectionFirstM;
    ivec2 hit = ivec2(-1);
    for (int i = 0; i < kReflectionSteps; ++i, t0 = t, t *= kReflectionGrowth) {
        vec2 cp;
        if (!projectToCanvas(o + t * r, cp)) break;
        ivec2 c = ivec2(floor(cp + 0.5));
        if (any(lessThan(c, ivec2(0))) || any(greaterThanEqual(c, ivec2(canvas.xy)))) break;
        vec4 S = texelFetch(gPosition, c, 0);
        if (int(S.w + 0.5) == ORIGIN_NONE) continue;
        float behind = length(o + t * r - cameraPos.xyz) - length(S.xyz - cameraPos.xyz);
        if (behind < 0.0 || behind > (t - t0) + 0.005) continue;  // in front, or far behind
        // The surface lies between t0 and t along the ray: bisect to the crossing.
        float lo = t0, hi = t;
        hit = c;
        for (int k = 0; k < kReflectionBisections; ++k) {
            float m = 0.5 * (lo + hi);
            if (!projectToCanvas(o + m * r, cp)) break;
            ivec2 cm = clamp(ivec2(floor(cp + 0.5)), ivec2(0), ivec2(canvas.xy) - 1);
            vec4 Sm = texelFetch(gPosition, cm, 0);
            bool past = int(Sm.w + 0.5) != ORIGIN_NONE &&
                        length(o + m * r - cameraPos.xyz) > length(Sm.xyz - cameraPos.xyz);
            if (past) {
                hi = m;
                hit = cm;
            } else {
                lo = m;
            }
        }
        break;
    }
    if (hit.x < 0) {
        if (envOrigin == ORIGIN_NONE) return vec3(0.0);
        return Fr * shIrradiance(r) / PI * exposure;
    }
    int origin = int(texelFetch(gPosition, hit, 0).w + 0.5);
    vec3 rv = texelFetch(lRv, hit, 0).rgb, rr = texelFetch(lR, hit, 0).rgb;
#ifndef MIRAGE_NO_CAUSTICS
    if (withCaustics != 0) {
        rv += texelFetch(causticRv, hit, 0).rgb;
        rr += texelFetch(causticR, hit, 0).rgb;
    }
#endif
    rv = max(rv, vec3(0.0)) * exposure;
    rr = max(rr, vec3(0.0)) * exposure;
    ivec2 camPx;
    if (origin != ORIGIN_REAL || !cameraPixelOfCanvas(hit, camPx)) return Fr * rv;
    vec3 c = texelFetch(cameraImage, camPx, 0).rgb;
    footageShare = Fr * c;
    return Fr * (c + guardedAlpha(c, rr) * (rv - rr));
}
#endif

#ifndef MIRAGE_DIFFUSE_ONLY  // the variant for frames without mirror / glass objects

// The variants of the specular code (CompositePass: llvmpipe pays for every branch's code, so
// what a pixel cannot need is compiled out): MIRAGE_REFLECTION_ONLY for the rectangles of
// mirrors and metals alone (no glass there: the refraction's weight is 0), MIRAGE_NO_SECOND_EXIT
// when the glass's second exit is off (SpecularOptions::secondExit).
#ifdef MIRAGE_REFLECTION_ONLY
const int kComponents = 1;
#else
const int kComponents = 2;
#endif

// Eqs. 6-11 at specular canvas pixel cpi for camera pixel colour ci; `footage` receives the part
// of the result that is video (CI, or the back-projected CI_bp); wholeCi: it is CI (all real).
// A rough mirror / metal / glass pixel's punctual highlight (direct.frag's rough-highlight
// variant, marked LR.a = 2) joins its specular light: L'_rv and L'_r, as the direct light routes it.
vec3 compositeSpecular(ivec2 cpi, vec3 ci, bool pReal, out vec3 footage, out bool wholeCi) {
    vec3 ex = exposure;
    vec4 fuzzyBp = fuzzyOn != 0 ? texelFetch(fuzzyVideo, cpi, 0) : vec4(0.0);
    bool fuzzy = fuzzyBp.a > 0.5;
    vec4 highlightR = texelFetch(lR, cpi, 0);
    bool highlight = highlightR.a > 1.5;
    vec3 rv = max((fuzzy ? texelFetch(fuzzyRv, cpi, 0) : texelFetch(specRv, cpi, 0)).rgb,
                  vec3(0.0)) * ex;
    vec3 r = max((fuzzy ? texelFetch(fuzzyR, cpi, 0) : texelFetch(specR, cpi, 0)).rgb,
                 vec3(0.0)) * ex;
    if (highlight) {
        rv += max(texelFetch(lRv, cpi, 0).rgb, vec3(0.0)) * ex;
        r += max(highlightR.rgb, vec3(0.0)) * ex;
    }
    vec3 rRefl =
        clamp((fuzzy ? texelFetch(fuzzyRRefl, cpi, 0) : texelFetch(specRRefl, cpi, 0)).rgb * ex,
              vec3(0.0), r);
    vec3 env = max((fuzzy ? texelFetch(fuzzyLenv, cpi, 0) : texelFetch(lEnv, cpi, 0)).rgb,
                   vec3(0.0)) * ex;
#if !defined(MIRAGE_REFLECTION_ONLY) && !defined(MIRAGE_NO_SECOND_EXIT)
    // The glass's second exit: the pixel's own, after the rough pass's blur of L_env.
    vec4 refrW = texelFetch(refrWeight, cpi, 0);
    env += secondExitEnvironment(cpi, refrW.rgb, refrW.a, envMap, gPosition, gNormal, gEmissive,
                                 backPosition, backNormal, realSurfaces) * ex;
#endif
    bool envReal = envOrigin == ORIGIN_REAL;
    bool allReal = pReal;
    vec3 ciBp = vec3(0.0);
    footage = vec3(0.0);
    wholeCi = false;
    // The camera pixel each component's hit is seen at (valid: back-projected), and its weight.
    ivec2 seenAt[2] = ivec2[2](ivec2(0), ivec2(0));
    bool seen[2] = bool[2](false, false);
    vec3 weight[2] = vec3[2](vec3(0.0), vec3(0.0));
    for (int k = 0; k < kComponents; ++k) {
        vec4 P = k == 0 ? texelFetch(reflPosition, cpi, 0) : texelFetch(refrPosition, cpi, 0);
        vec3 w = (k == 0 ? texelFetch(reflWeight, cpi, 0) : texelFetch(refrWeight, cpi, 0)).rgb;
        if (all(lessThanEqual(w, vec3(0.0)))) continue;  // no such component
        int origin = int(P.w + 0.5);
        if (fuzzy) {  // the filtered video term stands for both components (below)
            if (origin != ORIGIN_REAL) allReal = allReal && origin == ORIGIN_NONE && envReal;
            continue;
        }
        if (origin == ORIGIN_NONE) {  // left the scene: L_env carries it
            allReal = allReal && envReal;
            continue;
        }
        if (origin != ORIGIN_REAL) {  // virtual hit: CI_r = 0 (Eq. 10)
            allReal = false;
            continue;
        }
        weight[k] = w;
        seen[k] = backProjectPixel(P.xyz, realSurfaces, canvasToCamera, cameraImage, depthEpsilon,
                                   seenAt[k]);
        if (!seen[k]) ciBp += k == 0 ? rRefl : max(r - rRefl, vec3(0.0));  // rendered real share
    }
    // The footage without its noise for the component that carries most of the pixel (the
    // weaker one, a glass's reflection of 4 % at normal incidence, keeps its own: its share of
    // the noise is the square of its weight), so that the 5x5 mean runs once per pixel.
    float share0 = seen[0] ? dot(weight[0], vec3(1.0)) : -1.0;
    float share1 = seen[1] ? dot(weight[1], vec3(1.0)) : -1.0;
    int strong = share1 > share0 ? 1 : 0;
    vec3 strongCi = texelFetch(cameraImage, seenAt[strong], 0).rgb, spread;
    if (denoiseFootage != 0)
        strongCi = footageMean(cameraImage, seenAt[strong], strongCi, noiseVarianceAt(strongCi),
                               spread);
    for (int k = 0; k < kComponents; ++k) {
        if (!seen[k]) continue;
        vec3 c = k == strong ? strongCi : texelFetch(cameraImage, seenAt[k], 0).rgb;
        ciBp += weight[k] * c;
        footage += weight[k] * c;
    }
    if (fuzzy) ciBp = max(fuzzyBp.rgb, vec3(0.0));  // the neighbours' resolved CI_bp, filtered
    if (fuzzy) footage = ciBp;
    vec3 dL = rv - r;  // Eq. 6
    if (allReal) {
        footage = ci;
        wholeCi = true;
        return ci + guardedAlpha(ci, r + (envReal ? env : vec3(0.0))) * dL;
    }
    return env + ciBp + guardedAlpha(ciBp, r) * dL;
}
#endif

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 ci = texelFetch(cameraImage, px, 0).rgb;
#ifdef MIRAGE_IDENTITY_REMAP  // no lens distortion, canvas = camera image: each pixel its own
    vec2 canvasPx = vec2(px);
#define MIRAGE_CANVAS_AT(tex) texelFetch(tex, cpi, 0)
#else
    vec2 canvasPx = texelFetch(remap, px, 0).xy;
#define MIRAGE_CANVAS_AT(tex) texture(tex, (canvasPx + 0.5) * canvas.zw)
#endif
    vec3 result = ci;
    float coverage = 0.0;
    vec3 footage = ci;
    float layer = 0.0;
#ifdef MIRAGE_TRANSLUCENT_REFLECTION
    // The variant that adds a translucent boundary's reflection (TranslucencyOptions::
    // surfaceReflection) runs over the translucent objects' rectangles after the others and
    // rewrites only their pixels (gEmissive.a = -IOR); it reads gPosition, gNormal, gEmissive and
    // canvasToCamera.
    float translucentIor = 0.0;
    if (canvasPx.x > -1000.0)
        translucentIor = -texelFetch(gEmissive, clamp(ivec2(floor(canvasPx + 0.5)), ivec2(0),
                                                       ivec2(canvas.xy) - 1), 0).a;
    if (!(translucentIor > 0.5)) discard;
#endif
    if (canvasPx.x > -1000.0 && showVirtual != 0) {
        ivec2 cpi = ivec2(floor(canvasPx + 0.5));
#if defined(MIRAGE_IDENTITY_REMAP) && defined(MIRAGE_DIFFUSE_ONLY)
        // direct.frag writes the pixel's origin into LRv.a (it skips only the specular pixels,
        // which this variant never draws): one read fewer.
        vec4 lrv = texelFetch(lRv, cpi, 0);
        int origin = int(lrv.a + 0.5);
        vec3 rv = lrv.rgb, r = texelFetch(lR, cpi, 0).rgb;
#else
        int origin = int(texelFetch(gPosition, cpi, 0).w + 0.5);
        vec4 lrv = MIRAGE_CANVAS_AT(lRv);
        vec3 rv = lrv.rgb, r = MIRAGE_CANVAS_AT(lR).rgb;
#endif
#ifndef MIRAGE_NO_CAUSTICS  // the variant for frames without a caustic pass never reads them
        if (withCaustics != 0) {
            rv += MIRAGE_CANVAS_AT(causticRv).rgb;
            r += MIRAGE_CANVAS_AT(causticR).rgb;
        }
#endif
        rv = max(rv, vec3(0.0)) * exposure;
        r = max(r, vec3(0.0)) * exposure;
#ifndef MIRAGE_DIFFUSE_ONLY
        int slot = int(texelFetch(gEmissive, cpi, 0).a + 0.5) - 1;
        if (slot >= 0 && origin != ORIGIN_NONE) {
            bool wholeCi;
            result = compositeSpecular(cpi, ci, origin == ORIGIN_REAL, footage, wholeCi);
            coverage = origin == ORIGIN_VIRTUAL ? 1.0 : 0.5;
            layer = wholeCi ? 0.0 : float(2 + slot);
        } else
#endif
        if (origin == ORIGIN_VIRTUAL) {
            // Straight through a translucent object (no refraction at its boundary) the ray
            // meets what this camera pixel shows. Bilinear reads blend the code with a
            // neighbour's origin at the silhouette: clamped.
            float seeThrough = clamp((lrv.a - float(ORIGIN_VIRTUAL)) / kSeeThroughScale, 0.0, 1.0);
            footage = seeThrough * ci;
            result = rv + footage;
#ifdef MIRAGE_TRANSLUCENT_REFLECTION  // the translucent pixels' variant (CompositePass)
            vec3 reflectedFootage;
            result += boundaryReflection(cpi, translucentIor, reflectedFootage);
            footage += reflectedFootage;
#endif
            coverage = 1.0;
            layer = 1.0;
        } else {
            vec3 t = smoothstep(vec3(0.0), vec3(alphaFadeLr), r);
            vec3 ratio = min(ci / max(r, vec3(1e-6)), vec3(alphaMax));
            vec3 alpha = mix(vec3(1.0), ratio, t);
            result = ci + alpha * (rv - r);
            coverage = origin == ORIGIN_REAL ? 0.5 : 0.0;
        }
    }
    if (!allFinite(result)) result = vec3(0.0);
    result = max(result, vec3(0.0));
    outLinear = vec4(result, coverage);
    outSrgb = vec4(clamp(result, 0.0, 1.0), 1.0);
    outFootage = vec4(allFinite(footage) ? max(footage, vec3(0.0)) : vec3(0.0), layer);
}
