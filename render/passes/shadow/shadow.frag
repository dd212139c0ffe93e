#version 450 core
#include "common.glsl"
#include "lighting.glsl"
// Writes the occluder distance of one shadow layer and, for reflective shadow maps (Dachsbacher
// & Stamminger 2005), what a VPL there needs: the reflected radiant intensity per unit solid
// angle of the light (flux / steradian, linear RGB), the surface normal facing the light, the
// world position and whether the surface is real.
layout(std430, binding = kBindingMaterials) readonly buffer Materials { GpuMaterial materials[]; };
uniform int lightIndex;
uniform int materialIndex;
uniform int origin;
in vec3 worldPos;
in vec3 worldNormal;
in vec2 uv;
layout(binding = kUnitBaseColorMap) uniform sampler2D baseColorMap;  // sRGB texture: samples are linear
// The glass layer of this light layer (shadow_glass.frag), rendered first; -1 = no glass.
layout(binding = kUnitShadowGlassLayer) uniform sampler2DArray glassLayers;
uniform int glassLayer;
uniform float glassTexelsPerTexel;  // glass-layer texels per texel of this raster (RSM at rsmSize)
layout(location = 0) out float outDistance;  // metres from the light (see lightDistance)
layout(location = 1) out vec4 outFlux;       // rgb W/sr * albedo (W/m^2 * albedo for dir.), a = real
layout(location = 2) out vec4 outNormal;     // xyz world normal facing the light, w = 1 on a
                                             // mirror or glass (a VPL there follows the photon)
layout(location = 3) out vec4 outPosition;   // xyz world position (m), w = 1

void main() {
    const int li = lightIndex;
    outDistance = lightDistance(li, worldPos);
    GpuMaterial m = materials[materialIndex];
    bool directional = lights[li].type == LIGHT_DIRECTIONAL;
    vec3 toLight = directional ? -lights[li].direction
                               : normalize(lights[li].position - worldPos);
    vec3 n = normalize(worldNormal);
    if (!allFinite(n)) n = toLight;
    if (dot(n, toLight) < 0.0) n = -n;
    float dist = length(lights[li].position - worldPos);
    float atten = directional ? 1.0 : spotAttenuation(li, -toLight) * rangeWindow(li, dist);
    vec3 diffuseAlbedo = (m.baseColor.rgb * texture(baseColorMap, uv).rgb) * (1.0 - clamp(m.metallic, 0.0, 1.0));
    // Glass transmits instead of scattering diffusely (KHR_materials_transmission): only the
    // opaque share bounces into VPLs.
    diffuseAlbedo *= 1.0 - clamp(m.transmission, 0.0, 1.0);
    vec3 flux = lights[li].radiantIntensity * atten * diffuseAlbedo;
    if (glassLayer >= 0) {  // behind glass the light arrives coloured by it
        vec4 g = texelFetch(glassLayers, ivec3(ivec2(gl_FragCoord.xy * glassTexelsPerTexel), glassLayer), 0);
        if (outDistance > g.a + 1e-3) flux *= exp(min(g.rgb, vec3(0.0)));
    }
    outFlux = vec4(flux, origin == ORIGIN_REAL ? 1.0 : 0.0);
    outNormal = vec4(n, m.specular != 0 ? 1.0 : 0.0);
    outPosition = vec4(worldPos, 1.0);
}
