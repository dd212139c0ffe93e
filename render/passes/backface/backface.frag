#version 450 core
#include "common.glsl"
// Back faces of the specular objects (Wyman 2005's first pass): only fragments whose outward
// normal faces away from the camera are kept, the nearest of them wins the depth test.
uniform int specularSlot;
in vec3 worldPos;
in vec3 worldNormal;
in vec2 uv;
layout(location = 0) out vec4 outPosition;  // xyz world (m); w = specular slot + 1
layout(location = 1) out vec4 outNormal;    // xyz world outward unit normal
void main() {
    vec3 n = normalize(worldNormal);
    if (!allFinite(n)) n = vec3(0.0, 1.0, 0.0);
    if (dot(n, cameraPos.xyz - worldPos) > 0.0) discard;  // a front face
    outPosition = vec4(worldPos, float(specularSlot + 1));
    outNormal = vec4(n, 0.0);
}
