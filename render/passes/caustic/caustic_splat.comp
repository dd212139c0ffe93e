#version 450 core
#include "common.glsl"
#include "passes/caustic/caustic.glsl"
// Caustic buffer (Knecht 2013 Sec. 5.2): every photon of the photon G-buffers is splatted as a
// quad around its receiver hit, in camera space, into a fixed-point irradiance buffer with
// integer atomics (on llvmpipe scattering is ~10x cheaper in compute than as GL_POINTS).
// One invocation per photon texel; z = 2 x light layer + (0 reflected, 1 refracted).
//
// Quad size after Wyman 2008: the photon's footprint on the receiver is the spacing of its
// neighbouring photons' hits (their divergence from the light through the object); the kernel
// radius is quadScale x that spacing, at least 0.75 pixel (stretched by 1 / cos on a surface seen
// obliquely) and at most kMaxQuadPx pixels. The
// kernel is Epanechnikov in WORLD distance from the hit, so a pixel whose G-buffer surface is not
// near the hit (an occluder in front, another surface behind) gets nothing: depth rejection
// against the G-buffer. Weights are normalised over the pixels the photon reaches: the photon's
// power P lands as irradiance E_i = P w_i / sum_j (w_j A_j) (A = the pixel's surface area, m^2),
// so sum_i E_i A_i = P whatever the quad's size (a caustic focused to one pixel keeps its
// energy and nothing more). Specular pixels (mirror / glass) receive nothing.
// Output: 6 layers of uint irradiance x fixedScale: L_rv rgb (power x visibility), L_r rgb
// (power x real-path visibility: light, object and — at resolve time — receiver real).
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = kUnitSplatReflHit) uniform sampler2DArray reflHit;
layout(binding = kUnitSplatReflPower) uniform sampler2DArray reflPower;
layout(binding = kUnitSplatRefrHit) uniform sampler2DArray refrHit;
layout(binding = kUnitSplatRefrPower) uniform sampler2DArray refrPower;
layout(binding = kUnitSplatPosition) uniform sampler2D gPosition;  // xyz world, w = origin
layout(binding = kUnitSplatNormal) uniform sampler2D gNormal;
layout(binding = kUnitSplatEmissive) uniform sampler2D gEmissive;  // a = specular slot + 1
layout(r32ui, binding = kImageCausticAccum) uniform uimage2DArray accum;
// The canvas tiles (kCausticTileSize pixels square) the kernels reach (1), so that the resolve
// shades those only.
layout(r32ui, binding = kImageCausticPhotonTiles) uniform writeonly uimage2D photonTiles;
uniform int mapSize;
uniform float quadScale;   // kernel radius in photon spacings
uniform float fixedScale;  // irradiance (W/m^2) -> integer units
// Kernel radius cap (pixels): bounds the cost of photons spread wide (the ~4 % a glass reflects
// spreads over the table, each photon's kernel would reach 8 px and more). 2 px: the glass-alone
// frame's splat 3.7x cheaper than 8 px at the same error (docs/caustics.md, "Cost").
const int kMaxQuadPx = 2;
// The most pixels a kernel reaches from its centre: the cap, or the smallest kernel stretched on
// a surface seen obliquely (0.75 px / cos, cos >= 0.2), whichever is larger.
const int kMaxReachPx = 4;
// A photon scattered over a rough surface's lobe (photonFromRoughLobe) lands among neighbours
// from elsewhere in the lobe: its spacing is the glow's, and its kernel may reach kRoughReachPx
// so that the sparse photons of a wide glow overlap instead of speckling it (8 px: a photon near
// the image's edge puts its whole power into the few pixels in view; docs/caustics.md, "Rough
// surfaces", has the measurements). Only reflected photons are marked (photon_gbuffer.frag).
const int kRoughReachPx = 4;

// Surface area (m^2) of canvas pixel px whose surface is x with normal n: the pixel's solid
// angle cos^3 / (fx fy) times distance^2 / |cos| at the surface.
float pixelArea(vec3 x, vec3 n, float fx, float fy) {
    vec3 toCam = cameraPos.xyz - x;
    float dist = length(toCam);
    float z = max((viewMatrix * vec4(x, 1.0)).z, 1e-4);
    float cosS = max(abs(dot(n, toCam / max(dist, 1e-6))), 0.05);
    return z * z * z / (dist * fx * fy * cosS);
}

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (t.x >= mapSize || t.y >= mapSize) return;
    int layer = int(gl_GlobalInvocationID.z) / 2;
    bool refracted = (gl_GlobalInvocationID.z & 1u) == 1u;
    ivec3 tl = ivec3(t, layer);
    vec4 hit = refracted ? texelFetch(refrHit, tl, 0) : texelFetch(reflHit, tl, 0);
    vec4 pw = refracted ? texelFetch(refrPower, tl, 0) : texelFetch(reflPower, tl, 0);
    vec3 powerRv, powerR;
    if (!photonPowers(hit, pw, powerRv, powerR)) return;
    float spacing = refracted ? photonSpacing(refrHit, tl, mapSize, hit.xyz)
                              : photonSpacing(reflHit, tl, mapSize, hit.xyz);
    // Project the hit onto the canvas.
    vec4 c = viewProj * vec4(hit.xyz, 1.0);
    if (c.w <= 1e-6) return;
    vec2 cp = (c.xy / c.w * 0.5 + 0.5) * canvas.xy - 0.5;
    float fx = abs(projMatrix[0][0]) * 0.5 * canvas.x, fy = abs(projMatrix[1][1]) * 0.5 * canvas.y;
    float pixelWorld = c.w / fx;  // m per pixel at the hit's depth (facing the camera)
    // On a surface seen obliquely a pixel's footprint stretches by 1 / cos: the smallest kernel
    // must still reach a pixel centre, or the photon would be lost.
    ivec2 centre = ivec2(floor(cp + 0.5));
    vec3 nc = texelFetch(gNormal, clamp(centre, ivec2(0), ivec2(canvas.xy) - 1), 0).xyz;
    float cosC = abs(dot(nc, normalize(cameraPos.xyz - hit.xyz)));
    float rMin = 0.75 * pixelWorld / clamp(cosC, 0.2, 1.0);
    bool rough = photonFromRoughLobe(hit);
    float capPx = rough ? float(kRoughReachPx) : float(kMaxQuadPx);
    float r = clamp(quadScale * spacing, rMin, max(rMin, capPx * pixelWorld));
    int rPx = min(int(ceil(r / pixelWorld)), rough ? kRoughReachPx : kMaxReachPx);
    ivec2 lo = max(centre - rPx, ivec2(0)), hi = min(centre + rPx, ivec2(canvas.xy) - 1);
    if (any(greaterThan(lo, hi))) return;
    // The weights of the pixels reached, kept for the second loop (which then reads no G-buffer
    // texel again): 0 where the pixel has no surface near the hit or is a specular pixel.
    float weights[(2 * kRoughReachPx + 1) * (2 * kRoughReachPx + 1)];
    int n = 0;
    float r2 = r * r, sumWA = 0.0;
    for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
            float w = 0.0;
            vec4 g = texelFetch(gPosition, ivec2(x, y), 0);
            // Not a specular pixel (mirror / glass: emissive a > 0.5), a surface near the hit.
            if (int(g.w + 0.5) != ORIGIN_NONE && texelFetch(gEmissive, ivec2(x, y), 0).a <= 0.5) {
                vec3 dv = g.xyz - hit.xyz;
                w = max(1.0 - dot(dv, dv) / r2, 0.0);
                if (w > 0.0)
                    sumWA += w * pixelArea(g.xyz, texelFetch(gNormal, ivec2(x, y), 0).xyz, fx, fy);
            }
            weights[n++] = w;
        }
    if (!(sumWA > 0.0) || isinf(sumWA)) return;
    for (int ty = lo.y / kCausticTileSize; ty <= hi.y / kCausticTileSize; ++ty)
        for (int tx = lo.x / kCausticTileSize; tx <= hi.x / kCausticTileSize; ++tx)
            imageStore(photonTiles, ivec2(tx, ty), uvec4(1u));
    vec3 eRv = powerRv * (fixedScale / sumWA), eR = powerR * (fixedScale / sumWA);
    const float kMaxAdd = 268435456.0;  // 2^28: one photon can never wrap a counter
    n = 0;
    for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
            float w = weights[n++];
            if (w <= 0.0) continue;
            uvec3 a = uvec3(min(eRv * w, vec3(kMaxAdd)) + 0.5);
            uvec3 b = uvec3(min(eR * w, vec3(kMaxAdd)) + 0.5);
            ivec2 px = ivec2(x, y);
            if (a.r > 0u) imageAtomicAdd(accum, ivec3(px, 0), a.r);
            if (a.g > 0u) imageAtomicAdd(accum, ivec3(px, 1), a.g);
            if (a.b > 0u) imageAtomicAdd(accum, ivec3(px, 2), a.b);
            if (b.r > 0u) imageAtomicAdd(accum, ivec3(px, 3), b.r);
            if (b.g > 0u) imageAtomicAdd(accum, ivec3(px, 4), b.g);
            if (b.b > 0u) imageAtomicAdd(accum, ivec3(px, 5), b.b);
        }
}
