#version 450 core
#include "common.glsl"
// The nearest BACK faces of the specular objects seen from a spot light (Wyman 2005's first pass,
// from the light instead of the camera): the refracted photons' exit search
// (refractTwoInterfaces in passes/specular/specular.glsl) marches through this buffer.
uniform int lightIndex;
uniform int specularSlot;
in vec3 worldPos;
in vec3 worldNormal;
in vec2 uv;
layout(location = 0) out vec4 outPosition;  // xyz world (m); w = specular slot + 1
layout(location = 1) out vec4 outNormal;    // xyz world outward unit normal
void main() {
    vec3 n = normalize(worldNormal);
    if (!allFinite(n)) n = vec3(0.0, 1.0, 0.0);
    if (dot(n, lights[lightIndex].position - worldPos) > 0.0) discard;  // a front face
    outPosition = vec4(worldPos, float(specularSlot + 1));
    outNormal = vec4(n, 0.0);
}
