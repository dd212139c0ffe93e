#version 450 core
#include "common.glsl"
// G-buffer geometry: mesh-local position/normal -> world (metres, glTF axes) -> camera clip.
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUv;
uniform mat4 model;         // world-from-mesh
uniform mat4 normalMatrix;  // inverse transpose of model
out vec3 worldPos;
out vec3 worldNormal;
out vec2 uv;
#ifdef MIRAGE_GBUFFER_MATERIAL
// The draw's material, read once per vertex and handed on flat: llvmpipe reads a storage buffer
// per fragment lane even at a uniform index, which cost the G-buffer pass about a fifth of its
// time when gbuffer.frag read it per pixel.
layout(std430, binding = kBindingMaterials) readonly buffer Materials { GpuMaterial materials[]; };
uniform int materialIndex;
flat out vec4 materialBaseMetallic;     // rgb linear base colour, a = metallic
flat out vec4 materialEmissiveRough;    // rgb linear emitted radiance, a = roughness
flat out float materialTranslucentIor;  // a participating medium's boundary IOR (>= 1), else 0
#endif
void main() {
    vec4 wp = model * vec4(inPosition, 1.0);
    worldPos = wp.xyz;
    worldNormal = mat3(normalMatrix) * inNormal;
    uv = inUv;
    gl_Position = viewProj * wp;
#ifdef MIRAGE_GBUFFER_MATERIAL
    GpuMaterial m = materials[materialIndex];
    materialBaseMetallic = vec4(m.baseColor.rgb, m.metallic);
    materialEmissiveRough = vec4(m.emissive, m.roughness);
    materialTranslucentIor = m.translucent == 1 ? max(m.ior, 1.0) : 0.0;
#endif
}
