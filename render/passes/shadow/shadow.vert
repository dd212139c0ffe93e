#version 450 core
#include "common.glsl"
// Shadow map / reflective shadow map geometry: mesh-local -> world -> one light layer's clip.
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUv;
uniform mat4 model;
uniform mat4 normalMatrix;
uniform mat4 lightViewProj;  // world -> clip of this shadow layer
out vec3 worldPos;
out vec3 worldNormal;
out vec2 uv;
void main() {
    vec4 wp = model * vec4(inPosition, 1.0);
    worldPos = wp.xyz;
    worldNormal = mat3(normalMatrix) * inNormal;
    uv = inUv;
    gl_Position = lightViewProj * wp;
}
