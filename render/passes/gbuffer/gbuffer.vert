#version 450 core
#include "common.glsl"
// G-buffer geometry: mesh-local position/normal -> world (metres, glTF axes) -> camera clip.
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
uniform mat4 model;         // world-from-mesh
uniform mat4 normalMatrix;  // inverse transpose of model
out vec3 worldPos;
out vec3 worldNormal;
void main() {
    vec4 wp = model * vec4(inPosition, 1.0);
    worldPos = wp.xyz;
    worldNormal = mat3(normalMatrix) * inNormal;
    gl_Position = viewProj * wp;
}
