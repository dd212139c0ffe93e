#version 450 core
#include "common.glsl"
#include "lighting.glsl"
#include "passes/specular/specular.glsl"
// Glass in a shadow layer: every glass surface the light's ray crosses adds the logarithm of
// what it lets through, and the nearest one's distance is kept (additive blend on rgb, MIN on
// alpha; the layer is cleared to (0, 0, 0, 1e30)). Per crossing: sqrt(transmission) (the camera
// path applies the transmission once per two crossings), (1 - F) with F the Fresnel reflectance
// of `ior` at the light's incidence (the straight-line transmission of a shadow ray: the ray is
// not bent), the base colour (the reference tints each crossing by it). Beer-Lambert
// (KHR_materials_volume) is split over the crossings: entering at light distance d adds
// +sigma d, leaving adds -sigma d, so a closed surface sums to -sigma (d_exit - d_entry) with
// sigma = -ln(attenuationColor) / attenuationDistance (1/m). Normals are the mesh's outward
// normals (glTF). The lookups (lighting.glsl) clamp the sum to <= 0: an open surface never
// amplifies.
//
// A translucent object (translucent = 1) is drawn into the same layer: its boundary lets
// (1 - F) through per crossing as glass does, and its medium adds +k D(entry) where the ray
// enters and -k D(exit) where it leaves, D(x) the optical depth sigma_t integrated along the
// light's ray from the density grid's box to x (extinction * distance without a grid), so a
// closed surface sums to -k tau over the ray's inside segments (cavities, whose walls face
// inwards, add nothing). k = mediumShadowScale per channel (docs/translucency.md "Shadows").
layout(std430, binding = kBindingMaterials) readonly buffer Materials { GpuMaterial materials[]; };
uniform int lightIndex;
uniform int materialIndex;
uniform int origin;
uniform int translucent;         // 1: a translucent draw (the uniforms below), 0: glass
uniform float mediumExtinction;  // 1/m at density 1
uniform vec3 mediumShadowScale;  // k: ln T = -k tau
uniform float mediumIor;
uniform int mediumHasDensity;        // 0: density 1 everywhere inside
uniform mat4 mediumLocalFromWorld;   // world -> mesh-local (the density grid's units)
uniform vec3 densityMin;             // the grid's box, mesh-local
uniform vec3 densityMax;
uniform vec3 densityCells;           // samples per axis
layout(binding = kUnitShadowDensity) uniform sampler3D densityMap;  // R32F, trilinear
in vec3 worldPos;
in vec3 worldNormal;
in vec2 uv;
layout(binding = kUnitBaseColorMap) uniform sampler2D baseColorMap;  // sRGB texture: linear
layout(location = 0) out vec4 outGlass;  // rgb ln(transmittance) term, a = light distance (m)

// Integral of the density along the light's ray from where it enters the grid's box to p, in
// world metres (density times length): the midpoint rule with two samples per grid cell crossed.
float densityDepth(int li, vec3 p, float d) {
    vec3 a = lights[li].type == LIGHT_DIRECTIONAL ? p - lights[li].direction * d
                                                  : lights[li].position;
    vec3 aL = (mediumLocalFromWorld * vec4(a, 1.0)).xyz;
    vec3 pL = (mediumLocalFromWorld * vec4(p, 1.0)).xyz;
    vec3 dl = pL - aL;
    vec3 inv = 1.0 / max(abs(dl), vec3(1e-12)) * sign(dl + vec3(1e-30));
    vec3 t0 = (densityMin - aL) * inv, t1 = (densityMax - aL) * inv;
    float lo = max(max(max(min(t0.x, t1.x), min(t0.y, t1.y)), min(t0.z, t1.z)), 0.0);
    float hi = min(min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z)), 1.0);
    if (!(hi > lo)) return 0.0;
    vec3 extent = max(densityMax - densityMin, vec3(1e-12));
    vec3 cellsCrossed = abs(dl) * (hi - lo) / extent * densityCells;
    int n = clamp(int(ceil(2.0 * max(max(cellsCrossed.x, cellsCrossed.y), cellsCrossed.z))), 1,
                  512);
    float sum = 0.0;
    for (int k = 0; k < n; ++k) {
        vec3 q = aL + dl * (lo + (hi - lo) * (float(k) + 0.5) / float(n));
        sum += texture(densityMap, (q - densityMin) / extent).r;
    }
    return sum * (hi - lo) * length(p - a) / float(n);
}

void main() {
    const int li = lightIndex;
    float d = lightDistance(li, worldPos);
    if (translucent == 1) {
        bool directional = lights[li].type == LIGHT_DIRECTIONAL;
        vec3 toLight =
            directional ? -lights[li].direction : normalize(lights[li].position - worldPos);
        vec3 n = normalize(worldNormal);
        float cosL = allFinite(n) ? dot(n, toLight) : 1.0;
        float Ft = 1.0 - fresnelDielectric(max(abs(cosL), 1e-4), max(mediumIor, 1e-3));
        // Optical depth from the light's side to this crossing (the same origin along the ray).
        float D = mediumExtinction * (mediumHasDensity == 1 ? densityDepth(li, worldPos, d) : d);
        vec3 logT =
            vec3(log(max(Ft, 1e-6))) + (cosL >= 0.0 ? 1.0 : -1.0) * mediumShadowScale * D;
        outGlass = vec4(logT, d);
        return;
    }
    GpuMaterial m = materials[materialIndex];
    bool directional = lights[li].type == LIGHT_DIRECTIONAL;
    vec3 toLight = directional ? -lights[li].direction : normalize(lights[li].position - worldPos);
    vec3 n = normalize(worldNormal);
    float cosL = allFinite(n) ? dot(n, toLight) : 1.0;
    bool entering = cosL >= 0.0;
    float F = fresnelDielectric(max(abs(cosL), 1e-4), max(m.ior, 1e-3));
    float trans = clamp(m.transmission, 0.0, 1.0) * (1.0 - clamp(m.metallic, 0.0, 1.0));
    vec3 base = clamp(m.baseColor.rgb * texture(baseColorMap, uv).rgb, 0.0, 1.0);
    vec3 logT = log(max(vec3(sqrt(trans) * (1.0 - F)) * base, vec3(1e-6)));
    if (m.attenuationDistance > 0.0) {
        vec3 sigma = -log(clamp(m.attenuationColor, vec3(1e-6), vec3(1.0))) / m.attenuationDistance;
        logT += entering ? sigma * d : -sigma * d;
    }
    outGlass = vec4(logT, d);
}
