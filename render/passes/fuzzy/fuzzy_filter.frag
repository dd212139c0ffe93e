#version 450 core
#include "common.glsl"
#include "passes/fuzzy/fuzzy.glsl"
// One direction of the separable fuzzy-reflection filter (Kulikova and Dmitriev Eqs. 1-5), over
// the rough-metal pixels of the canvas; run twice (rows, then columns of the row-filtered result).
// For pixel x with surface point a, reflected hit b (GBuf_refl), camera distance s and hit
// distance r:
//   L(x) = sum_x' f(x, x') L0(x') / sum_x' f(x, x'),  f = cos^p J            (Eqs. 1, 3)
//   J = angle between (b - a) and (b' - a), b' the neighbour's hit (a direction on a miss)
//   p = phongExponent(roughness)   (fuzzy.glsl: the stated GGX -> Phong mapping; roughness per
//       pixel from the G-buffer: factor x metallicRoughness texture)
//   kernel: neighbours whose camera ray is within alpha = Theta' / (1 + s / r) of x's   (Eq. 4),
//   radius alpha x focal length in pixels (Eq. 5), Theta' = min(Theta, 2.5 / sqrt(p)): the
//   cone bound Theta (RendererOptions::fuzzyConeDeg), or the lobe's 2.5 sigma when narrower.
// Rough glass (kRoughGlass): the same filter on what is seen THROUGH it, with the refracted
// geometry: the origin is the centre pixel's exit point P2 = a + T1 d_in (T1 = Snell at the
// front face, d_in the distance inside from GBuf_refr), b and b' the refracted hits, p the
// transmitted lobe's exponent (fuzzy.glsl), s the camera distance plus d_in. Its (weak) Fresnel
// reflection is blurred with the same weights. Where nothing is refracted (TIR at the front face)
// the pixel is filtered as a reflection.
// Separable approximation: the second pass weights each column tap by its own hit. A kernel
// wider than `taps` per side is sampled every ceil(radius / taps) pixels. Only taps on the same
// object (specular slot) and within 10 % of x's camera distance count, so the filter never
// reaches across the object's silhouette or a fold of it. Radius below one pixel (roughness ->
// 0): x alone, exactly the unfiltered value.
in vec2 uv;
layout(binding = kUnitFuzzyPosition) uniform sampler2D gPosition;  // xyz world, w = origin
layout(binding = kUnitFuzzyEmissive) uniform sampler2D gEmissive;  // a = specular slot + 1
layout(binding = kUnitFuzzyReflHit) uniform sampler2D reflHit;     // xyz hit, w = origin
layout(binding = kUnitFuzzyRefrHit) uniform sampler2D refrHit;     // GBuf_refr: xyz, w = origin
layout(binding = kUnitFuzzyRefrWeight) uniform sampler2D refrWeight;  // rgb eta2 T, a = d_in (m)
layout(binding = kUnitFuzzyNormal) uniform sampler2D gNormal;      // xyz unit normal, w = roughness
layout(binding = kUnitFuzzyInputFirst + 0) uniform sampler2D in0;  // L'_rv
layout(binding = kUnitFuzzyInputFirst + 1) uniform sampler2D in1;  // L'_r
layout(binding = kUnitFuzzyInputFirst + 2) uniform sampler2D in2;  // reflection share of L'_r
layout(binding = kUnitFuzzyInputFirst + 3) uniform sampler2D in3;  // L_env
layout(binding = kUnitFuzzyInputFirst + 4) uniform sampler2D in4;  // resolved video term
uniform ivec2 stepDir;     // (1, 0) rows, (0, 1) columns (canvas pixels)
uniform float coneBound;   // Theta (radians)
uniform float focalPx;     // canvas focal length (pixels per radian near the axis)
uniform int taps;          // taps per side
layout(location = 0) out vec4 out0;
layout(location = 1) out vec4 out1;
layout(location = 2) out vec4 out2;
layout(location = 3) out vec4 out3;
layout(location = 4) out vec4 out4;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    // Every pixel the filter leaves passes its input through (this pass writes the next version
    // of the L' buffers: the composite reads it on every specular pixel), the video term 0.
    out0 = texelFetch(in0, px, 0);
    out1 = texelFetch(in1, px, 0);
    out2 = texelFetch(in2, px, 0);
    out3 = texelFetch(in3, px, 0);
    out4 = vec4(0.0);
    int slot = roughSlot(texelFetch(gEmissive, px, 0).a);
    if (slot < 0) return;
    vec3 a = texelFetch(gPosition, px, 0).xyz;
    float s = length(a - cameraPos.xyz), sa = s;
    GpuMaterial m = materials[specularDraws[slot].material];
    // Per pixel, as the G-buffer wrote it: the factor x the metallicRoughness texture's G, so one
    // object can be smooth in parts (a kernel of one pixel: exactly the mirror value) and rough
    // in others. Which objects are filtered is decided by the factor (Material::isRoughReflector).
    vec4 nr = texelFetch(gNormal, px, 0);
    float roughness = clamp(nr.w, 0.0, 1.0);
    // Which rays the kernel compares (see above): the refracted ones through rough glass, else
    // the reflected ones; o is where they leave the object.
    vec3 o = a;
    bool refracted = false;
    float p = phongExponent(roughness);
    if (specularDraws[slot].rough == kRoughGlass) {
        vec4 W = texelFetch(refrWeight, px, 0);
        vec3 T1 = refract((a - cameraPos.xyz) / max(s, 1e-9), nr.xyz,
                          1.0 / max(m.ior, 1e-3));
        if (any(greaterThan(W.rgb, vec3(0.0))) && dot(T1, T1) > 0.5) {
            refracted = true;
            o = a + normalize(T1) * max(W.a, 0.0);
            s += max(W.a, 0.0);
            p = transmissionExponent(roughness, max(m.ior, 1e-3));
        }
    }
    vec4 hit = refracted ? texelFetch(refrHit, px, 0) : texelFetch(reflHit, px, 0);
    vec3 u = hitDirection(o, hit);
    float r = hitDistance(o, hit);
    float theta = min(coneBound, 2.5 * inversesqrt(max(p, 1e-12)));
    float alpha = theta / (1.0 + s / max(r, 1e-6));               // Eq. 4 (radians)
    float radius = min(alpha * focalPx, 4096.0);                  // Eq. 5 (pixels)
    int stride = max(1, int(ceil(radius / float(taps))));
    int n = min(taps, int(floor(radius / float(stride))));
    ivec2 size = ivec2(canvas.xy);
    vec4 s0 = vec4(0.0), s1 = vec4(0.0), s2 = vec4(0.0), s3 = vec4(0.0), s4 = vec4(0.0);
    float wsum = 0.0;
    for (int k = -n; k <= n; ++k) {
        ivec2 q = px + k * stride * stepDir;
        if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
        if (k != 0) {
            if (int(texelFetch(gEmissive, q, 0).a + 0.5) - 1 != slot) continue;  // other object
            float sq = length(texelFetch(gPosition, q, 0).xyz - cameraPos.xyz);
            if (abs(sq - sa) > 0.1 * sa) continue;  // a fold of the object: not its neighbour
        }
        vec4 hq = refracted ? texelFetch(refrHit, q, 0) : texelFetch(reflHit, q, 0);
        float c = k == 0 ? 1.0 : dot(u, hitDirection(o, hq));
        float w = k == 0 ? 1.0 : (c > 0.0 ? pow(min(c, 1.0), p) : 0.0);  // Eq. 3
        if (!(w > 0.0)) continue;
        s0 += w * texelFetch(in0, q, 0);
        s1 += w * texelFetch(in1, q, 0);
        s2 += w * texelFetch(in2, q, 0);
        s3 += w * texelFetch(in3, q, 0);
        s4 += w * texelFetch(in4, q, 0);
        wsum += w;
    }
    if (wsum <= 1.0) {  // only the centre tap: its values exactly (no reciprocal round-off)
        out0 = texelFetch(in0, px, 0);
        out1 = texelFetch(in1, px, 0);
        out2 = texelFetch(in2, px, 0);
        out3 = texelFetch(in3, px, 0);
        out4 = vec4(texelFetch(in4, px, 0).rgb, 1.0);
        return;
    }
    float inv = 1.0 / wsum;  // wsum > 1: the centre tap and at least one neighbour
    out0 = s0 * inv;
    out1 = s1 * inv;
    out2 = s2 * inv;
    out3 = s3 * inv;
    out4 = vec4((s4 * inv).rgb, 1.0);
}
