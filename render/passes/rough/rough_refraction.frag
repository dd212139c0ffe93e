#version 450 core
#include "common.glsl"
#include "passes/specular/specular.glsl"
#include "passes/rough/gsr.glsl"
// Rough refraction (Zeng and Wyman, "Real-time rough refraction via LEAN mapping and Gaussian sum
// reduction", after de Rousiers et al. 2011), per rough-glass canvas pixel, over the sharp
// two-interface path of the specular passes (front point a, normal n, T1, exit P2 = a + T1 d_in,
// exit direction T2, hit b at distance r, all from GBuf_refr). Angles in radians, per-axis
// variances in rad^2, world frame (metres).
//  1. Front BTDF lobe: GGX width alpha = roughness^2 tilts a facet by sigma_h^2 = alpha^2 / 2 per
//     axis; a tilt d turns the refracted ray by k1 d, k1 = 1 - cos_i / (ior cos_t) (1 - 1/ior
//     head-on), so T1 spreads by s1^2 = k1^2 sigma_h^2.
//  2. Carried to the back surface: footprint std s1 d_in (m), in canvas pixels s1 d_in f / |P2 -
//     eye|; the LEAN chains are read at the level of that footprint, L = log2(sqrt(12) sigma_px)
//     (a box of 2^L texels has the std 2^L / sqrt(12): the Lee et al. 2008 mapping of a Gaussian
//     to a mip level).
//  3. Back NDF at that footprint: LEAN - the moments' mean and covariance Sigma = E[n n^T] -
//     E[n] E[n]^T projected onto the tangent plane of the central back normal N0 (one lobe);
//     GSR - the 4x4 texels two levels finer, each a Gaussian, merged by Runnalls' formula
//     (gsr.glsl) within each of `subdivisions` azimuth sectors: one lobe per sector.
//  4. Outgoing lobe of each (convolution of Gaussians: variances add): T2 turns by g_in per unit
//     of T1's turn and by g_n per unit of back-normal tilt, g_in = ior cos_in / cos_out, g_n =
//     g_in - 1 (total internal reflection, followed once as in the sharp path: 1 and 2), so
//     Sigma_out = g_in^2 s1^2 I + g_n^2 (Sigma_back + sigma_h^2 I) (the back face is as rough
//     as the front: the reference's GGX dielectric); the lobe's mean turns T2 with its mean
//     normal (exactly: refract about the tilted normal).
//  5. What the lobe sees, blurred by a prefiltered lookup: the rough glass's own resolved buffers
//     (L'_rv, L'_r, its reflection share, L_env and the video term CI_bp, i.e. the impostor
//     hits' rendered radiance, the environment and the back-projected camera image, each as the
//     composite would take it for a sharp pixel) in coverage-weighted mip chains
//     (rough_prefilter.frag), fetched around the pixel shifted by the lobe's mean turn, at the
//     canvas radius the footprint maps to: a turn of the exit ray by angle x moves what it sees
//     by x f r / (s + d_in + r) canvas pixels (a flat slab's magnification; s the camera
//     distance, f the focal length in pixels; misses: x f), and the level is Lee et al.'s from the
//     lobe's major std. With ray differentials (footprintModel 1) the map is the inverse of how
//     far the sharp path's seen point moves per canvas pixel (the neighbours' exits), never
//     wider than the slab's: on a sphere's rim the lobe stays on the rim's own pixels.
//     Anisotropic lobes are sums of isotropic taps along the major axis (Mavridis and
//     Papaioannou 2011). Looking the hits up in the image of the glass rather than
//     in the camera image or the environment map keeps the blur continuous where the sharp hit
//     changes kind (a box edge against the sky: one pixel sees the box, its neighbour a miss).
// The glass's weak Fresnel reflection is in the same buffers and gets the same blur. A lookup of
// std below half a pixel at the pixel itself is the pixel's value exactly, so roughness -> 0
// gives the smooth path to the digit. Every other pixel passes the input through.
in vec2 uv;
layout(std430, binding = kBindingMaterials) readonly buffer Materials { GpuMaterial materials[]; };
layout(std430, binding = kBindingSpecularDraws) readonly buffer SpecularDraws { GpuSpecularDraw specularDraws[]; };
layout(binding = kUnitRoughPosition) uniform sampler2D gPosition;     // xyz world, w = origin
layout(binding = kUnitRoughNormal) uniform sampler2D gNormal;         // xyz normal, w = roughness
layout(binding = kUnitRoughEmissive) uniform sampler2D gEmissive;     // a = slot + 1
layout(binding = kUnitRoughReflHit) uniform sampler2D reflHit;        // xyz hit / dir, w = origin
layout(binding = kUnitRoughReflWeight) uniform sampler2D reflWeight;  // eta1
layout(binding = kUnitRoughRefrHit) uniform sampler2D refrHit;        // xyz hit / dir, w = origin
layout(binding = kUnitRoughRefrWeight) uniform sampler2D refrWeight;  // eta2 T, a = d_in (m)
layout(binding = kUnitRoughLeanFirst + 0) uniform sampler2D leanMean;      // c n, a = c
layout(binding = kUnitRoughLeanFirst + 1) uniform sampler2D leanSquares;   // c n^2
layout(binding = kUnitRoughLeanFirst + 2) uniform sampler2D leanProducts;  // c (xy, xz, yz)
layout(binding = kUnitRoughPrefilteredFirst + 0) uniform sampler2D preRv;  // g L'_rv, a = g
layout(binding = kUnitRoughPrefilteredFirst + 1) uniform sampler2D preR;
layout(binding = kUnitRoughPrefilteredFirst + 2) uniform sampler2D preRRefl;
layout(binding = kUnitRoughPrefilteredFirst + 3) uniform sampler2D preEnv;
layout(binding = kUnitRoughPrefilteredFirst + 4) uniform sampler2D preVideo;  // CI_bp
layout(binding = kUnitRoughInputFirst + 0) uniform sampler2D in0;  // L'_rv (pass-through)
layout(binding = kUnitRoughInputFirst + 1) uniform sampler2D in1;  // L'_r
layout(binding = kUnitRoughInputFirst + 2) uniform sampler2D in2;  // reflection share of L'_r
layout(binding = kUnitRoughInputFirst + 3) uniform sampler2D in3;  // L_env
layout(binding = kUnitRoughInputFirst + 4) uniform sampler2D in4;  // video term (fuzzy) or 0
uniform int method;           // 0: LEAN, 1: GSR
uniform int footprintModel;   // 0: a flat slab's magnification, 1: ray differentials
uniform int subdivisions;     // GSR: azimuth sectors (1..kMaxSectors)
uniform float focalPx;        // canvas focal length (pixels per radian near the axis)
uniform float maxLevel;       // the chains' last mip level
layout(location = 0) out vec4 out0;
layout(location = 1) out vec4 out1;
layout(location = 2) out vec4 out2;
layout(location = 3) out vec4 out3;
layout(location = 4) out vec4 out4;

const float kSqrt12 = 3.4641016;
const int kMaxSectors = 8;
const int kMaxEwaTaps = 4;

// Mip level of a Gaussian of std sigma (texels of level 0), clamped to the chain.
float levelOf(float sigmaTexels, float lastLevel) {
    return clamp(log2(max(kSqrt12 * sigmaTexels, 1.0)), 0.0, lastLevel);
}

// An anisotropic Gaussian (covariance c in the basis t, b; rad^2) as `count` equal-weight
// isotropic ones of std `sigma` spaced `spacing` apart along `axis` (world), centred: the
// centres' variance (spacing^2 (count^2 - 1) / 12) plus sigma^2 is the major variance. Nearly
// isotropic lobes: one tap of the major std.
struct Ewa {
    vec3 axis;
    float spacing;
    float sigma;
    int count;
};
// From the covariance's eigen decomposition (gsrEigen: major and minor variance, angle).
Ewa ewaFromEigen(vec3 e, vec3 t, vec3 b) {
    Ewa p;
    p.axis = cos(e.z) * t + sin(e.z) * b;
    float major = sqrt(e.x), minor = sqrt(e.y);
    p.count = 1;
    p.spacing = 0.0;
    p.sigma = major;
    if (major > 1.5 * minor) {
        p.count = clamp(int(ceil(major / max(minor, 1e-9))), 2, kMaxEwaTaps);
        p.spacing = sqrt(max(e.x - e.y, 0.0) * 12.0 / float(p.count * p.count - 1));
        p.sigma = max(minor, 0.5 * p.spacing);  // no gaps between the taps
    }
    return p;
}
Ewa ewaPlan(vec3 c, vec3 t, vec3 b) { return ewaFromEigen(gsrEigen(c), t, b); }
float ewaOffset(Ewa p, int j) { return (float(j) - 0.5 * float(p.count - 1)) * p.spacing; }

// What the lobe sees: the five prefiltered buffers (L'_rv, L'_r, reflection share, L_env, CI_bp)
// around canvas point cp, EWA taps (canvas offsets = angle x toCanvas along the major axis's
// projection), each at the level of its isotropic std. A lookup of std below half a pixel at the
// pixel itself is the pixel's values exactly (texelFetch of level 0).
void lobeLookup(ivec2 px, vec2 cp, Ewa p, vec2 axisPx, float toCanvas, out vec4 v[5]) {
    float level = levelOf(p.sigma * toCanvas, maxLevel);
    // Within its own pixel (the major std, taps' spread included, below half a pixel): the
    // pixel's values.
    float majorVar = p.sigma * p.sigma + p.spacing * p.spacing * float(p.count * p.count - 1) / 12.0;
    if (majorVar * toCanvas * toCanvas < 0.25 &&
        all(lessThanEqual(abs(cp - vec2(px)), vec2(1e-3)))) {
        v[0] = texelFetch(preRv, px, 0);
        v[1] = texelFetch(preR, px, 0);
        v[2] = texelFetch(preRRefl, px, 0);
        v[3] = texelFetch(preEnv, px, 0);
        v[4] = texelFetch(preVideo, px, 0);
        return;
    }
    vec4 acc[5];
    for (int i = 0; i < 5; ++i) acc[i] = vec4(0.0);
    for (int j = 0; j < p.count; ++j) {
        vec2 st = (cp + axisPx * (ewaOffset(p, j) * toCanvas) + 0.5) * canvas.zw;
        acc[0] += textureLod(preRv, st, level);
        acc[1] += textureLod(preR, st, level);
        acc[2] += textureLod(preRRefl, st, level);
        acc[3] += textureLod(preEnv, st, level);
        acc[4] += textureLod(preVideo, st, level);
    }
    // Coverage-weighted: divide by the covered fraction (all five share it); nothing covered
    // (the lobe left the glass's image entirely): the pixel's own values.
    for (int i = 0; i < 5; ++i) v[i] = acc[0].a > 1e-3 ? acc[i] / acc[0].a : vec4(0.0);
    if (!(acc[0].a > 1e-3)) {
        v[0] = texelFetch(preRv, px, 0);
        v[1] = texelFetch(preR, px, 0);
        v[2] = texelFetch(preRRefl, px, 0);
        v[3] = texelFetch(preEnv, px, 0);
        v[4] = texelFetch(preVideo, px, 0);
    }
}

// The sharp path's exit point P2 and direction T2 at canvas pixel q, when q shows the same
// rough glass (draw slot) with a refracted component; false otherwise.
bool sharpExit(ivec2 q, int slot, float eta, out vec3 P2q, out vec3 T2q) {
    P2q = vec3(0.0);
    T2q = vec3(0.0);
    if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, ivec2(canvas.xy)))) return false;
    if (int(texelFetch(gEmissive, q, 0).a + 0.5) - 1 != slot) return false;
    vec4 W = texelFetch(refrWeight, q, 0);
    if (all(lessThanEqual(W.rgb, vec3(0.0)))) return false;
    vec4 Hq = texelFetch(refrHit, q, 0);
    bool missQ = int(Hq.w + 0.5) == ORIGIN_NONE;
    if (missQ && dot(Hq.xyz, Hq.xyz) <= 0.25) return false;
    vec3 aq = texelFetch(gPosition, q, 0).xyz;
    vec3 dq = normalize(aq - cameraPos.xyz);
    vec3 T1q = refract(dq, texelFetch(gNormal, q, 0).xyz, 1.0 / eta);
    if (dot(T1q, T1q) < 0.5) return false;
    P2q = aq + normalize(T1q) * max(W.a, 0.0);
    vec3 e = missQ ? Hq.xyz : Hq.xyz - P2q;
    if (!(dot(e, e) > 1e-12)) return false;
    T2q = normalize(e);
    return allFinite(P2q) && allFinite(T2q);
}

// How what the exit ray sees moves from pixel to pixel (ray differentials; Igehy 1999): the
// seen point P2 + r T2 of a neighbour, with this pixel's hit distance r, moves across T2 by
// dP2 + r dT2 per canvas pixel, i.e. by (dP2 / r + dT2) radians as seen from the exit, per axis
// in the basis u, v across T2. Central differences, one-sided at the glass's edge; false for an
// axis with neither neighbour (the caller keeps the slab model).
bool seenDifferential(ivec2 px, ivec2 step, int slot, float eta, vec3 P2, vec3 T2, float invR,
                      out vec3 dSeen) {
    vec3 Pp, Tp, Pm, Tm;
    bool okP = sharpExit(px + step, slot, eta, Pp, Tp);
    bool okM = sharpExit(px - step, slot, eta, Pm, Tm);
    if (okP && okM) dSeen = 0.5 * ((Pp - Pm) * invR + (Tp - Tm));
    else if (okP) dSeen = (Pp - P2) * invR + (Tp - T2);
    else if (okM) dSeen = (P2 - Pm) * invR + (T2 - Tm);
    else dSeen = vec3(0.0);
    return okP || okM;
}

// The map from a turn of the exit ray (radians, across T2 in the basis u, v) to canvas pixels:
// the inverse of the seen point's differential G (seenDifferential, both axes), where both axes
// have a neighbour of the same glass and G is not singular (a seen point that barely moves
// between pixels would spread a lobe over the whole canvas: the slab model holds there).
bool differentialMap(ivec2 px, int slot, float eta, vec3 P2, vec3 T2, float invR, vec3 u, vec3 v,
                     float toCanvas, out mat2 turnToPx) {
    turnToPx = mat2(0.0);
    vec3 dX, dY;
    if (!seenDifferential(px, ivec2(1, 0), slot, eta, P2, T2, invR, dX) ||
        !seenDifferential(px, ivec2(0, 1), slot, eta, P2, T2, invR, dY))
        return false;
    mat2 G = mat2(vec2(dot(dX, u), dot(dX, v)), vec2(dot(dY, u), dot(dY, v)));
    if (!(abs(determinant(G)) > 1e-3 / (toCanvas * toCanvas))) return false;
    turnToPx = inverse(G);
    return allFinite(vec3(turnToPx[0], turnToPx[1].x)) && allFinite(vec3(turnToPx[1].y));
}

// The back normals' Gaussian (slopes in the tangent plane t, b of N0; covariance) at a texel of
// `level` (normalised moments), weight = covered fraction w.
GsrLobe momentLobe(vec4 m1, vec4 sq, vec4 pr, vec3 N0, vec3 t, vec3 b, float w) {
    if (!(m1.a > 1e-4)) return gsrLobe(vec2(0.0), vec3(0.0), 0.0);
    vec3 mean = m1.xyz / m1.a;
    vec3 s2 = sq.xyz / m1.a, sp = pr.xyz / m1.a;
    mat3 S = mat3(s2.x, sp.x, sp.y, sp.x, s2.y, sp.z, sp.y, sp.z, s2.z);  // E[n n^T]
    mat3 C = S - outerProduct(mean, mean);
    float cz = max(dot(mean, N0), 0.1);
    vec2 slope = vec2(dot(mean, t), dot(mean, b)) / cz;
    vec3 cov = vec3(dot(t, C * t), dot(b, C * b), dot(t, C * b)) / (cz * cz);
    cov.xy = max(cov.xy, vec2(0.0));
    return gsrLobe(slope, cov, w);
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    out0 = texelFetch(in0, px, 0);
    out1 = texelFetch(in1, px, 0);
    out2 = texelFetch(in2, px, 0);
    out3 = texelFetch(in3, px, 0);
    out4 = texelFetch(in4, px, 0);
    int slot = int(texelFetch(gEmissive, px, 0).a + 0.5) - 1;
    if (slot < 0 || specularDraws[slot].rough != kRoughGlass) return;
    vec4 W2 = texelFetch(refrWeight, px, 0);
    vec4 H = texelFetch(refrHit, px, 0);
    int origin = int(H.w + 0.5);
    bool miss = origin == ORIGIN_NONE;
    // Nothing refracted (TIR at the front face): the sharp values.
    if (all(lessThanEqual(W2.rgb, vec3(0.0))) || (miss && dot(H.xyz, H.xyz) <= 0.25)) return;
    GpuMaterial m = materials[specularDraws[slot].material];
    float eta = max(m.ior, 1e-3);
    vec3 a = texelFetch(gPosition, px, 0).xyz;
    vec4 Nf = texelFetch(gNormal, px, 0);
    vec3 n = Nf.xyz;
    float roughness = clamp(Nf.w, 0.0, 1.0);  // per pixel: factor x metallicRoughness texture
    float s = length(a - cameraPos.xyz);
    vec3 d = (a - cameraPos.xyz) / max(s, 1e-9);
    vec3 T1 = refract(d, n, 1.0 / eta);
    if (dot(T1, T1) < 0.5) return;
    T1 = normalize(T1);
    float din = max(W2.a, 0.0);
    vec3 P2 = a + T1 * din;
    vec3 T2 = miss ? H.xyz : H.xyz - P2;
    float r = miss ? 1e30 : length(T2);
    T2 = dot(T2, T2) > 1e-12 ? normalize(T2) : T1;

    // 1. The front lobe.
    float alpha = roughness * roughness;
    float sh2 = 0.5 * alpha * alpha;
    float cosI = clamp(dot(n, -d), 1e-4, 1.0);
    float cosT = sqrt(max(1.0 - (1.0 - cosI * cosI) / (eta * eta), 1e-8));
    float k1 = 1.0 - cosI / (eta * cosT);
    float s1sq = k1 * k1 * sh2;

    // 2. Its footprint on the back surface; the central back normal N0 (the sharp path's texel).
    vec2 cp2;
    if (!projectToCanvas(P2, cp2)) cp2 = vec2(px);
    ivec2 size0 = ivec2(canvas.xy);
    ivec2 q0 = clamp(ivec2(floor(cp2 + 0.5)), ivec2(0), size0 - 1);
    vec4 M0 = texelFetch(leanMean, q0, 0);
    vec3 N0 = M0.a > 0.5 ? M0.xyz : (miss ? vec3(0.0) : eta * T1 - T2);
    if (!(dot(N0, N0) > 1e-8) || !allFinite(N0)) N0 = T1;
    N0 = normalize(N0);
    if (dot(N0, T1) < 1e-3) N0 = normalize(N0 + T1 * (1e-3 - dot(N0, T1)));
    vec3 t = normalize(cross(N0, abs(N0.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0)));
    vec3 b = cross(N0, t);
    float footPx = sqrt(s1sq) * din * focalPx / max(length(P2 - cameraPos.xyz), 1e-6);
    float levelB = levelOf(footPx, maxLevel);

    // 3. The back NDF over the footprint: one lobe (LEAN) or one per sector (GSR).
    GsrLobe lobes[kMaxSectors];
    int sectors = method == 1 ? clamp(subdivisions, 1, kMaxSectors) : 1;
    for (int k = 0; k < kMaxSectors; ++k) lobes[k] = gsrLobe(vec2(0.0), vec3(0.0), 0.0);
    vec2 st2 = (cp2 + 0.5) * canvas.zw;
    if (method == 1 && footPx >= 0.5) {
        int lg = max(int(floor(levelB)) - 2, 0);
        float scale = exp2(float(lg));
        // Level lg's size from the canvas (GL: floor(size / 2^lg), at least 1), not
        // textureSize(leanMean, lg): llvmpipe answers that query for a group of fragments with
        // one fragment's lod, so where neighbouring pixels differ in lg (an iso-line of the
        // footprint across the slab) it returned another level's size and the clamp below
        // pulled the window off the back face.
        ivec2 sizeG = max(ivec2(canvas.xy) >> lg, ivec2(1));
        // cp2 in level-lg texel units (texel q's centre at q): the 4 x 4 texels whose centres
        // are nearest, two on each side.
        ivec2 base = ivec2(floor((cp2 + 0.5) / scale - 1.5));
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                ivec2 q = clamp(base + ivec2(i, j), ivec2(0), sizeG - 1);
                vec2 centre = (vec2(q) + 0.5) * scale - 0.5;  // canvas pixels
                vec2 dq = centre - cp2;
                float w = exp(-0.5 * dot(dq, dq) / (footPx * footPx));
                vec4 m1 = texelFetch(leanMean, q, lg);
                GsrLobe g = momentLobe(m1, texelFetch(leanSquares, q, lg),
                                       texelFetch(leanProducts, q, lg), N0, t, b, w * m1.a);
                // A texel of another face (mean normal beyond 60 degrees of N0) is outside the
                // small-angle slope model: its own lobe would point anywhere.
                if (m1.a > 1e-4 && dot(normalize(m1.xyz), N0) < 0.5) g.weight = 0.0;
                int k = gsrSector(g.mean, sectors);
                lobes[k] = gsrMerge(lobes[k], g);
            }
        float gathered = 0.0;
        for (int k = 0; k < kMaxSectors; ++k) gathered += lobes[k].weight;
        if (!(gathered > 0.0)) {  // nothing of the object's back faces there: LEAN's lobe
            lobes[0] = momentLobe(textureLod(leanMean, st2, levelB),
                                  textureLod(leanSquares, st2, levelB),
                                  textureLod(leanProducts, st2, levelB), N0, t, b, 1.0);
            sectors = 1;
        }
    } else if (footPx >= 0.5) {
        lobes[0] = momentLobe(textureLod(leanMean, st2, levelB), textureLod(leanSquares, st2, levelB),
                              textureLod(leanProducts, st2, levelB), N0, t, b, 1.0);
        sectors = 1;
    } else {  // a footprint within one texel: the sharp path's texel, one normal (no covariance)
        lobes[0] = gsrLobe(vec2(0.0), vec3(0.0), 1.0);
        sectors = 1;
    }

    // 4-5. Each lobe out through the back surface, and what it sees.
    float cosIn = clamp(dot(T1, N0), 1e-4, 1.0);
    float sin2Out = (1.0 - cosIn * cosIn) * eta * eta;
    bool tir = sin2Out >= 1.0;
    float gIn = tir ? 1.0 : eta * cosIn / max(sqrt(1.0 - sin2Out), 0.05);
    float gN = tir ? 2.0 : gIn - 1.0;
    vec3 T2c = tir ? reflect(T1, -N0) : refract(T1, -N0, eta);  // the lobes' reference direction
    vec3 camRight = vec3(viewMatrix[0][0], viewMatrix[1][0], viewMatrix[2][0]);
    vec3 camDown = vec3(viewMatrix[0][1], viewMatrix[1][1], viewMatrix[2][1]);
    float toCanvas = focalPx * (miss ? 1.0 : r / (s + din + r));  // canvas px per radian
    // The ray differentials' map from a turn of the exit ray (across T2, in u, v) to canvas
    // pixels; else the flat slab's magnification toCanvas.
    vec3 u = camRight - T2 * dot(camRight, T2);
    u = dot(u, u) > 1e-8 ? normalize(u) : normalize(cross(T2, camDown));
    vec3 v = cross(T2, u);
    mat2 turnToPx;
    bool differential = footprintModel == 1 &&
                        differentialMap(px, slot, eta, P2, T2, miss ? 0.0 : 1.0 / max(r, 1e-6),
                                        u, v, toCanvas, turnToPx);
    // The differentials only narrow the slab's footprint (the rim of a curved glass, where the
    // exit ray sweeps the surroundings within a pixel or two): where they would widen it, the
    // neighbours are another face of the object (a slab's edge) or a focus, and the first-order
    // map does not hold.
    float maxPxPerRad = toCanvas;
    vec4 sum[5];
    for (int i = 0; i < 5; ++i) sum[i] = vec4(0.0);
    float wsum = 0.0;
    for (int k = 0; k < sectors; ++k) {
        GsrLobe g = lobes[k];
        if (!(g.weight > 0.0)) continue;
        bool centred = g.mean == vec2(0.0);  // exactly the sharp direction
        vec2 cp = vec2(px);
        if (!centred) {
            vec3 Nk = normalize(N0 + g.mean.x * t + g.mean.y * b);
            vec3 Tk = tir ? reflect(T1, -Nk) : refract(T1, -Nk, eta);
            if (dot(Tk, Tk) < 0.5) Tk = reflect(T1, -Nk);
            vec3 dT = normalize(Tk) - T2c;  // the lobe's turn of the exit ray
            if (allFinite(dT)) {
                vec2 shift = differential ? turnToPx * vec2(dot(dT, u), dot(dT, v))
                                          : toCanvas * vec2(dot(dT, camRight), dot(dT, camDown));
                float cap = maxPxPerRad * length(dT);
                if (dot(shift, shift) > cap * cap) shift *= cap / length(shift);
                cp += shift;
            }
        }
        vec3 cov = gIn * gIn * s1sq * vec3(1.0, 1.0, 0.0) +
                   gN * gN * (g.cov + sh2 * vec3(1.0, 1.0, 0.0));
        Ewa p;
        vec2 axisPx;
        float pxPerUnit = toCanvas;
        if (differential) {
            // The lobe's covariance from t, b to u, v, then to canvas pixels.
            mat2 M = mat2(vec2(dot(t, u), dot(t, v)), vec2(dot(b, u), dot(b, v)));
            mat2 A = turnToPx * M;
            mat2 C = mat2(vec2(cov.x, cov.z), vec2(cov.z, cov.y));
            mat2 P = A * C * transpose(A);
            vec3 e = gsrEigen(vec3(P[0][0], P[1][1], P[0][1]));
            e.xy = min(e.xy, vec2(maxPxPerRad * maxPxPerRad * gsrEigen(cov).x));
            p = ewaFromEigen(e, vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0));
            axisPx = p.axis.xy;
            pxPerUnit = 1.0;
        } else {
            p = ewaPlan(cov, t, b);
            axisPx = vec2(dot(p.axis, camRight), dot(p.axis, camDown));
        }
        vec4 v5[5];
        lobeLookup(px, cp, p, axisPx, pxPerUnit, v5);
        for (int i = 0; i < 5; ++i) sum[i] += g.weight * v5[i];
        wsum += g.weight;
    }
    if (!(wsum > 0.0)) return;
    float inv = 1.0 / wsum;
    vec3 o[5];
    for (int i = 0; i < 5; ++i) {
        o[i] = sum[i].rgb * inv;
        if (!allFinite(o[i])) return;
    }
    out0 = vec4(o[0], 1.0);
    out1 = vec4(o[1], 1.0);
    out2 = vec4(o[2], 1.0);
    out3 = vec4(o[3], 1.0);
    out4 = vec4(max(o[4], vec3(0.0)), 1.0);
}
