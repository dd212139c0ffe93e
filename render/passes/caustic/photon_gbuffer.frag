#version 450 core
#include "common.glsl"
#include "lighting.glsl"
#include "passes/specular/specular.glsl"
#include "passes/impostor/trace.glsl"
// Photon G-buffers PGBuf_refl and PGBuf_refr of one spot light (Knecht 2013 Sec. 5.2, Wyman &
// Davis 2006): the specular objects rendered from the light through a frustum fitted to them;
// every texel is one photon. Its power by pixel counting (Shah et al. 2007): the texel's solid
// angle x the light's radiant intensity x the spot profile and range window, times the reflection
// weight (reflected photon) or the two-interface transmittance with Beer-Lambert absorption
// (refracted photon) — the same functions as the camera path (specular.glsl). Each photon is
// traced from the object to its receiver through the impostors (traceSurroundings), as the
// camera path's reflected and refracted rays are. Frames: world (glTF, metres).
//
// Light inside the object (the nearest surface seen from the light faces away from it): one
// refraction on the way out (TIR: one internal reflection), absorption over the distance from
// the light; no reflected photon.
layout(binding = kUnitPhotonMaterials) uniform samplerBuffer materialTexels;  // GpuMaterial[]
layout(binding = kUnitPhotonSpecularDraws) uniform samplerBuffer specularDrawTexels;  // GpuSpecularDraw[]
layout(binding = kUnitPhotonBackPosition) uniform sampler2D backPosition;  // xyz, w = slot + 1
layout(binding = kUnitPhotonBackNormal) uniform sampler2D backNormal;      // outward
layout(binding = kUnitPhotonShadowAll) uniform sampler2DArray shadowAll;
layout(binding = kUnitPhotonShadowReal) uniform sampler2DArray shadowReal;
uniform int lightIndex;
uniform int specularSlot;
uniform int origin;           // of the specular object drawn
uniform int materialIndex;    // (MaterialDraw; the slot's material is used)
uniform mat4 lightViewProj;   // world -> clip of the fitted frustum
uniform float mapSize;        // texels per side
uniform float tanHalf;        // tan of the frustum's half angle
uniform int marchSteps;
uniform int roughPhotons;  // 1: rough surfaces scatter their photons over the GGX lobe
in vec3 worldPos;
in vec3 worldNormal;
in vec2 uv;
layout(location = 0) out vec4 outReflHit;    // xyz receiver (m), w = 4 origin + real visibility
layout(location = 1) out vec4 outReflPower;  // rgb W, a = visibility (all occluders)
layout(location = 2) out vec4 outRefrHit;
layout(location = 3) out vec4 outRefrPower;
layout(location = 4) out uvec4 outReflSurface;  // the receiver, for reflected / refracted VPLs
layout(location = 5) out uvec4 outRefrSurface;

// Receiver normal (facing the photon) and diffuse albedo as halves (Resource::PhotonSurface*).
uvec4 photonSurface(SurroundingHit h) {
    if (!h.hit) return uvec4(0u);
    vec3 n = allFinite(h.normal) ? h.normal : vec3(0.0);
    vec3 a = clamp(h.albedo, 0.0, 1.0) * (1.0 - clamp(h.metallic, 0.0, 1.0));
    return uvec4(packHalf2x16(n.xy), packHalf2x16(vec2(n.z, a.r)), packHalf2x16(a.gb), 0u);
}

// w = 4 x origin + real visibility, + 2 when the photon was scattered over a rough lobe (the
// splat then widens its kernel: caustic.glsl's photonFromRoughLobe).
vec4 photonHit(SurroundingHit h, float realVis, bool roughLobe) {
    if (!h.hit || !allFinite(h.position)) return vec4(0.0);  // leaves the modelled scene
    return vec4(h.position,
                4.0 * float(h.origin) + clamp(realVis, 0.0, 1.0) + (roughLobe ? 2.0 : 0.0));
}

vec4 photonPower(vec3 power, float vis) {
    return vec4(allFinite(power) ? max(power, vec3(0.0)) : vec3(0.0), clamp(vis, 0.0, 1.0));
}

// A rough specular surface (roughness above the mirror threshold 0.05, docs/scene.md) scatters its
// photons over its GGX lobe instead of along the mirror / Snell ray, so its caustic and the
// reflected / refracted VPLs spread as the reference's microfacet BSDF spreads them (a rough
// mirror's caustic becomes a soft glow). Each photon takes one microfacet normal, sampled from
// the GGX distribution D(m) cos(m, n) of width alpha = roughness^2 (glTF) with a 2D R2
// low-discrepancy point of its texel index, so neighbouring photons cover the lobe evenly and a
// frame's photons are the same every frame (no flicker in the temporally smoothed caustic).
const float kRoughPhotonThreshold = 0.05;
vec3 ggxMicrofacetNormal(vec3 n, float alpha, vec2 u) {
    float phi = 2.0 * PI * u.x;
    float tan2 = alpha * alpha * u.y / max(1.0 - u.y, 1e-6);
    float cosT = inversesqrt(1.0 + tan2), sinT = sqrt(max(1.0 - cosT * cosT, 0.0));
    vec3 t = normalize(abs(n.y) < 0.9 ? cross(n, vec3(0.0, 1.0, 0.0)) : cross(n, vec3(1.0, 0.0, 0.0)));
    vec3 b = cross(n, t);
    return normalize(sinT * cos(phi) * t + sinT * sin(phi) * b + cosT * n);
}
// The photon's weight for a reflection about a microfacet normal m sampled as above: the
// microfacet BRDF x cos over the sampling density, G |i.m| / (|i.n| |m.n|) (Walter et al. 2007,
// Eq. 41; Fresnel applied by the caller), with the Smith-Schlick G of lighting.glsl's brdfCos.
float ggxReflectionWeight(vec3 n, vec3 m, vec3 wi, vec3 wo, float alpha) {
    float ni = max(dot(n, wi), 1e-4), no = dot(n, wo), mi = max(dot(m, wi), 0.0);
    if (no <= 0.0) return 0.0;  // below the surface: shadowed by the other facets
    float k = alpha * 0.5;
    float G = (ni / (ni * (1.0 - k) + k)) * (no / (no * (1.0 - k) + k));
    return min(G * mi / (ni * max(dot(m, n), 1e-4)), 4.0);
}
vec2 photonLowDiscrepancy(ivec2 texel) {
    float i = float(texel.y) * mapSize + float(texel.x) + 1.0;
    return fract(vec2(0.5) + i * vec2(0.7548776662466927, 0.5698402909980532));  // R2 sequence
}

void main() {
    outReflHit = vec4(0.0);
    outReflPower = vec4(0.0);
    outRefrHit = vec4(0.0);
    outRefrPower = vec4(0.0);
    outReflSurface = uvec4(0u);
    outRefrSurface = uvec4(0u);
    const int li = lightIndex;
    vec3 p = worldPos;
    vec3 d = p - lights[li].position;
    float dist = length(d);
    if (dist < 1e-6) return;
    d /= dist;
    vec3 nOut = normalize(worldNormal);
    if (!allFinite(nOut)) return;
    bool inside = dot(nOut, d) > 0.0;  // the light is inside the object
    vec3 n = inside ? -nOut : nOut;    // faces the light
    int slot = specularSlot;
    GpuSpecularDraw sd = specularDrawAt(specularDrawTexels, slot);
    GpuMaterial m = materialAt(materialTexels, sd.material);
    float cosL = clamp(dot(n, -d), 1e-4, 1.0);

    // Pixel counting: the texel's solid angle in the fitted frustum (square, tanHalf).
    vec2 ndc = gl_FragCoord.xy / mapSize * 2.0 - 1.0;
    float texelTan = 2.0 * tanHalf / mapSize;
    float solidAngle = texelTan * texelTan /
                       pow(1.0 + tanHalf * tanHalf * dot(ndc, ndc), 1.5);
    vec3 power = lights[li].radiantIntensity * spotAttenuation(li, d) * rangeWindow(li, dist) *
                 solidAngle;
    // Visibility from the light (occluders between light and object), both GI solutions.
    vec2 vis = shadowVisibility(shadowAll, shadowReal, li, p, cosL, lights[li].realOnlyMap == 1);
    float realVis = lights[li].isReal == 1 && origin == ORIGIN_REAL ? vis.y : 0.0;

    float transWeight = transmissionShare(m);
    float eta = max(m.ior, 1e-3);
    float eps = 1e-4 + 1e-4 * dist;  // ray offset against self-intersection (m)

    if (inside) {
        if (transWeight <= 0.0) return;
        float F = fresnelDielectric(-cosL, eta);  // from the inside
        vec3 T = refract(d, n, eta);               // n faces the light (inwards): ratio eta / 1
        if (F >= 1.0 || dot(T, T) < 0.5) {
            T = reflect(d, n);  // TIR: one internal reflection, then out (as the camera path)
            F = 0.0;
        }
        T = normalize(T);
        vec3 base = clamp(m.baseColor.rgb, 0.0, 1.0);
        vec3 absorb = vec3(1.0);
        if (m.attenuationDistance > 0.0)
            absorb = pow(max(m.attenuationColor, vec3(1e-6)), vec3(dist / m.attenuationDistance));
        SurroundingHit h = traceSurroundings(slot, p + T * eps, T);
        outRefrHit = photonHit(h, realVis, false);
        outRefrPower = photonPower(power * transWeight * (1.0 - F) * base * absorb, vis.x);
        outRefrSurface = photonSurface(h);
        return;
    }
    // The facet the photon meets: the surface itself, or on a rough surface one sampled from
    // its GGX lobe (both the reflected and the refracted photon leave by it).
    vec3 facet = n;
    float lobeWeight = 1.0;
    bool rough = roughPhotons == 1 && m.roughness > kRoughPhotonThreshold;
    if (rough) {
        float alpha = max(m.roughness * m.roughness, 1e-3);
        facet = ggxMicrofacetNormal(n, alpha, photonLowDiscrepancy(ivec2(gl_FragCoord.xy)));
        if (dot(facet, -d) <= 1e-4) facet = n;  // a back-facing facet: not met by the photon
        lobeWeight = ggxReflectionWeight(n, facet, -d, reflect(d, facet), alpha);
    }
    float cosF = clamp(dot(facet, -d), 1e-4, 1.0);
    vec3 r = reflect(d, facet);
    SurroundingHit hr = traceSurroundings(slot, p + n * eps, r);
    outReflHit = lobeWeight > 0.0 ? photonHit(hr, realVis, rough) : vec4(0.0);
    outReflPower = photonPower(power * reflectionWeight(m, cosF, transWeight) * lobeWeight, vis.x);
    outReflSurface = photonSurface(hr);
    if (transWeight <= 0.0) return;
    vec3 P2, T2;
    float F1, F2, travelled;
    if (!refractTwoInterfaces(p, facet, d, slot, sd, eta, lightViewProj, lights[li].position,
                              vec2(mapSize), backPosition, backNormal, marchSteps, P2, T2, F1, F2,
                              travelled))
        return;
    SurroundingHit ht = traceSurroundings(slot, P2 + T2 * eps, T2);
    // The refracted photon leaves the glass beside it: a kernel wider than the smooth glass's 2
    // px would pour the light of the pixels the glass hides into the few in view around its
    // foot (0.746 against 0.709 of the smooth render's error over the rough tabletop's changed
    // pixels), so it splats as a sharp photon does.
    outRefrHit = photonHit(ht, realVis, false);
    outRefrPower = photonPower(power * refractionWeight(m, transWeight, F1, F2, travelled), vis.x);
    outRefrSurface = photonSurface(ht);
}
