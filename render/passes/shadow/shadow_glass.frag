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
layout(std430, binding = kBindingMaterials) readonly buffer Materials { GpuMaterial materials[]; };
uniform int lightIndex;
uniform int materialIndex;
uniform int origin;
in vec3 worldPos;
in vec3 worldNormal;
in vec2 uv;
layout(binding = kUnitBaseColorMap) uniform sampler2D baseColorMap;  // sRGB texture: linear
layout(location = 0) out vec4 outGlass;  // rgb ln(transmittance) term, a = light distance (m)

void main() {
    const int li = lightIndex;
    float d = lightDistance(li, worldPos);
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
