// Shared by the fuzzy-reflection shaders (include after common.glsl). World frame = glTF
// (metres, +Y up). Kulikova and Dmitriev, "Fuzzy reflections" (image-space filter): the mirror
// ray of every pixel is traced first (GBuf_refl); the reflection is then the weighted mean of
// the neighbours' mirror reflections, weight cos^p of the angle J between the pixel's own
// reflected ray and the ray from its surface point to the neighbour's hit (Eqs. 1, 3).
#ifndef MIRAGE_FUZZY_GLSL
#define MIRAGE_FUZZY_GLSL

layout(std430, binding = kBindingMaterials) readonly buffer Materials { GpuMaterial materials[]; };
layout(std430, binding = kBindingSpecularDraws) readonly buffer SpecularDraws { GpuSpecularDraw specularDraws[]; };

// 1: rough glass is filtered here too (RendererOptions::roughRefraction = Filter); 0: only
// rough metals (the rough-refraction pass, render/passes/rough, takes the glass).
uniform int filterGlass;

// The specular slot of a G-buffer pixel (gEmissive.a = slot + 1) if it shows a rough metal, or
// rough glass when filterGlass, else -1.
int roughSlot(float emissiveA) {
    int slot = int(emissiveA + 0.5) - 1;
    if (slot < 0) return -1;
    int rough = specularDraws[slot].rough;
    return rough == kRoughMetal || (rough == kRoughGlass && filterGlass != 0) ? slot : -1;
}

// Phong exponent p of the reflected-direction lobe from glTF perceptual roughness r: GGX / Beckmann
// width alpha = r^2 spreads half-vectors with sigma_h = alpha / sqrt(2), the reflected direction
// turns twice as far (sigma_J = sqrt(2) alpha), and cos^p J ~ exp(-p J^2 / 2) has sigma_J =
// 1 / sqrt(p): p = 1 / (2 alpha^2) - 1/2 (the -1/2 makes roughness 1 give p = 0, a flat kernel).
// Infinite at r = 0 (the weight of any J > 0 is then 0: the mirror).
float phongExponent(float roughness) {
    float a = roughness * roughness;
    return max(0.5 / max(a * a, 1e-30) - 0.5, 0.0);
}

// Phong exponent of the TRANSMITTED lobe of rough glass (both interfaces rough, as the
// reference's GGX dielectric): a facet tilt d turns the ray by d (1 - 1/ior) entering and by
// d (ior - 1) leaving, so with sigma_h = alpha / sqrt(2) per interface the exit ray spreads by
// sigma_t^2 = alpha^2 ((1 - 1/ior)^2 + (ior - 1)^2) / 2, and p = 1 / sigma_t^2. (ior 1.5:
// sigma_t = 0.42 alpha, a third of the reflected lobe's.) Infinite at roughness 0 or ior 1.
float transmissionExponent(float roughness, float ior) {
    float a = roughness * roughness;
    float k2 = 0.5 * ((1.0 - 1.0 / ior) * (1.0 - 1.0 / ior) + (ior - 1.0) * (ior - 1.0));
    return 1.0 / max(a * a * k2, 1e-30);
}

// Unit direction from surface point a to the reflected hit (GBuf_refl texel: xyz hit, w =
// origin; on a miss xyz is the ray's direction).
vec3 hitDirection(vec3 a, vec4 hit) {
    vec3 d = int(hit.w + 0.5) == ORIGIN_NONE ? hit.xyz : hit.xyz - a;
    float l = length(d);
    return l > 1e-9 ? d / l : vec3(0.0);
}

// r of Eq. 4: distance from the surface point to the hit (metres); a miss is infinitely far.
float hitDistance(vec3 a, vec4 hit) {
    return int(hit.w + 0.5) == ORIGIN_NONE ? 1e30 : length(hit.xyz - a);
}

#endif
