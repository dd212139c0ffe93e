#version 450 core
#include "common.glsl"
// G-buffer capture for traceSurroundings (all linear). Attachment 0 depends on the target:
// cube maps store the world position (m) + origin, impostors the surface's offset along the
// impostor's W axis (m, the height field) + origin. The normal is stored as modelled (not
// flipped): the tracer turns it toward the ray origin.
layout(std430, binding = kBindingMaterials) readonly buffer Materials { GpuMaterial materials[]; };
uniform int materialIndex;
uniform int origin;         // ORIGIN_REAL or ORIGIN_VIRTUAL
uniform int captureDepth;   // 0: cube map (position), 1: impostor (offset along depthAxis)
uniform vec4 depthAxis;     // xyz unit W axis (world), w = -dot(W, impostor centre)
in vec3 worldPos;
in vec3 worldNormal;
in vec2 uv;
layout(binding = kUnitBaseColorMap) uniform sampler2D baseColorMap;  // sRGB texture: samples are linear
layout(location = 0) out vec4 gPositionOrDepth;
layout(location = 1) out vec4 gNormal;    // xyz unit world normal, w = roughness
layout(location = 2) out vec4 gAlbedo;    // rgb linear base colour, a = metallic
layout(location = 3) out vec4 gEmissive;  // rgb linear emitted radiance
void main() {
    GpuMaterial m = materials[materialIndex];
    vec3 n = normalize(worldNormal);
    if (!allFinite(n)) n = vec3(0.0, 1.0, 0.0);
    if (captureDepth == 1)
        gPositionOrDepth = vec4(dot(depthAxis.xyz, worldPos) + depthAxis.w, float(origin), 0, 0);
    else
        gPositionOrDepth = vec4(worldPos, float(origin));
    gNormal = vec4(n, clamp(m.roughness, 0.02, 1.0));
    gAlbedo = vec4(m.baseColor.rgb * texture(baseColorMap, uv).rgb, clamp(m.metallic, 0.0, 1.0));
    gEmissive = vec4(m.emissive, 0.0);
}
