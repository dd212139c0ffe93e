#version 450 core
#include "common.glsl"
#include "passes/specular/specular.glsl"
#include "passes/impostor/trace.glsl"
// GBuf_refl (mode 0) and GBuf_refr (mode 1) of Knecht 2013 Sec. 5.1, from the camera's view:
// for every pixel where the primary G-buffer shows a mirror or glass object (slot > 0), the
// surface attributes of what the reflected / refracted ray hits, plus the Fresnel weight the
// radiance from there carries into the pixel.
//
// Reflection: r = reflect(-v, n) from the front surface p.
// Refraction, two interfaces (Wyman 2005): Snell at the front face (n1 = 1 outside, n2 = ior)
// gives T1; the exit point P2 is where T1 meets the object's back faces, found by marching T1
// through the back-face buffer (nearest back face per pixel) and refining by bisection — Wyman's
// distance estimate made exact for whatever the back-face buffer holds; when the march leaves
// the back faces' footprint the exit is taken on the object's bounding sphere. Snell at the back
// face (outward normal N2 from the back-face buffer) gives the exit ray T2.
//  - Total internal reflection at the back face (sin > 1/ior): the light path reflects inside;
//    we follow ONE internal reflection, T2 = reflect(T1, -N2), leaving from P2 with Fresnel 1
//    (no second refraction: the approximation is documented in docs/specular.md).
//  - TIR at the front face (only possible for ior < 1): everything is reflected (F1 = 1).
//  - ior = 1: T1 = T2 = the view ray and F1 = F2 = 0: the object vanishes except for absorption.
//  - Grazing views: cos clamped, refract() of GLSL never divides by zero; every output is
//    checked finite.
// Weight of the refracted radiance: transmission (1 - F1)(1 - F2) baseColour^2 (the reference
// tints each crossing by baseColour) x Beer-Lambert attenuationColour^(d / attenuationDistance)
// with d = |P2 - p| the distance travelled inside (KHR_materials_volume).
// Weight of the reflected radiance: Fresnel F1 (dielectric) or Schlick(baseColour) (mirror).
in vec2 uv;
layout(binding = kUnitSpecGbufMaterials) uniform samplerBuffer materialTexels;  // GpuMaterial[]
layout(binding = kUnitSpecGbufSpecularDraws) uniform samplerBuffer specularDrawTexels;  // GpuSpecularDraw[]
layout(binding = kUnitSpecGbufPosition) uniform sampler2D gPosition;
layout(binding = kUnitSpecGbufNormal) uniform sampler2D gNormal;
layout(binding = kUnitSpecGbufEmissive) uniform sampler2D gEmissive;  // a = specular slot + 1
layout(binding = kUnitSpecGbufBackPosition) uniform sampler2D backPosition;  // xyz world, w = slot + 1
layout(binding = kUnitSpecGbufBackNormal) uniform sampler2D backNormal;    // outward
#ifndef MIRAGE_SPECULAR_MODE  // SpecularGBufferPass compiles one program per mode
#define MIRAGE_SPECULAR_MODE 0
#endif
// A constant, not a uniform: llvmpipe would run both modes' code for every pixel.
const int mode = MIRAGE_SPECULAR_MODE;  // 0 = reflection, 1 = refraction
uniform int marchSteps;  // back-face march steps
layout(location = 0) out vec4 outPosition;  // hit xyz world (m) | ray direction on a miss;
                                            // w = hit origin (ORIGIN_NONE = miss)
layout(location = 1) out vec4 outNormal;    // hit unit normal (facing the ray), w = roughness
layout(location = 2) out vec4 outAlbedo;    // hit linear base colour, a = metallic
layout(location = 3) out vec4 outEmissive;  // hit emitted radiance, a = 1 on a specular pixel
layout(location = 4) out vec4 outWeight;    // rgb Fresnel x transmittance weight, a = distance
                                            // travelled inside (m, refraction)

void writeHit(SurroundingHit h, vec3 dir, vec3 weight, float inside) {
    if (h.hit && allFinite(h.position)) {
        outPosition = vec4(h.position, float(h.origin));
        outNormal = vec4(h.normal, clamp(h.roughness, 0.02, 1.0));
        outAlbedo = vec4(h.albedo, clamp(h.metallic, 0.0, 1.0));
        outEmissive = vec4(h.emissive, 1.0);
    } else {
        outPosition = vec4(dir, float(ORIGIN_NONE));
        outNormal = vec4(-dir, 1.0);
        outAlbedo = vec4(0.0);
        outEmissive = vec4(0.0, 0.0, 0.0, 1.0);
    }
    outWeight = vec4(allFinite(weight) ? max(weight, vec3(0.0)) : vec3(0.0),
                     isnan(inside) || isinf(inside) ? 0.0 : inside);
}

#ifdef MIRAGE_SPECULAR_TRACE_HALF
// Half-resolution trace (RendererOptions::specular.halfResolutionTrace): this fragment is a 2x2
// block of the canvas, traced from its representative, the block's first specular pixel (x then
// y), as specular_trace_fill.frag finds it again; -1 when the block has none.
ivec2 blockRepresentative(ivec2 block) {
    ivec2 size = textureSize(gEmissive, 0);
    for (int i = 0; i < 4; ++i) {
        ivec2 c = 2 * block + ivec2(i & 1, i >> 1);
        if (all(lessThan(c, size)) && texelFetch(gEmissive, c, 0).a >= 0.5) return c;
    }
    return ivec2(-1);
}
#endif

void main() {
#ifdef MIRAGE_SPECULAR_TRACE_HALF
    ivec2 px = blockRepresentative(ivec2(gl_FragCoord.xy));
    if (px.x < 0) {
        outPosition = outNormal = outAlbedo = outEmissive = outWeight = vec4(0.0);
        return;
    }
#else
    ivec2 px = ivec2(gl_FragCoord.xy);
#endif
    outPosition = vec4(0.0);
    outNormal = vec4(0.0);
    outAlbedo = vec4(0.0);
    outEmissive = vec4(0.0);
    outWeight = vec4(0.0);
    int slot = int(texelFetch(gEmissive, px, 0).a + 0.5) - 1;
    if (slot < 0) return;
    vec4 P = texelFetch(gPosition, px, 0);
    vec3 p = P.xyz;
    vec3 n = texelFetch(gNormal, px, 0).xyz;  // faces the camera (G-buffer convention)
    vec3 v = cameraPos.xyz - p;
    float vl = length(v);
    if (vl < 1e-6 || !allFinite(n)) return;
    v /= vl;
    vec3 d = -v;
    GpuSpecularDraw sd = specularDrawAt(specularDrawTexels, slot);
    GpuMaterial m = materialAt(materialTexels, sd.material);
    float cosV = clamp(dot(n, v), 1e-4, 1.0);  // grazing: clamped, never 0
    float transWeight = transmissionShare(m);
    float eta = max(m.ior, 1e-3);
    float eps = 1e-4 + 1e-4 * vl;  // ray offset against self-intersection (metres)

    if (mode == 0) {
        vec3 r = reflect(d, n);
        SurroundingHit h = traceSurroundings(slot, p + n * eps, r);
        writeHit(h, r, reflectionWeight(m, cosV, transWeight), 0.0);
        return;
    }
    if (transWeight <= 0.0) {
        outEmissive.a = 1.0;  // specular pixel, nothing refracted
        return;
    }
    vec3 P2, T2;
    float F1, F2, inside;
    if (!refractTwoInterfaces(p, n, d, slot, sd, eta, viewProj, cameraPos.xyz, canvas.xy,
                              backPosition, backNormal, marchSteps, P2, T2, F1, F2, inside)) {
        outEmissive.a = 1.0;  // TIR at the front face (ior < 1): all reflected
        return;
    }
    vec3 weight = refractionWeight(m, transWeight, F1, F2, inside);
    SurroundingHit h = traceSurroundings(slot, P2 + T2 * eps, T2);
    writeHit(h, T2, weight, inside);
}
