#version 450 core
// Impostor / cube-map capture: mesh-local -> world (metres, glTF axes) -> the capture's clip space
// (a cube face seen from the specular object's centre, or an impostor's orthographic box).
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUv;
uniform mat4 model;         // world-from-mesh
uniform mat4 normalMatrix;  // inverse transpose of model
uniform mat4 captureViewProj;  // world -> capture clip
out vec3 worldPos;
out vec3 worldNormal;
out vec2 uv;
void main() {
    vec4 wp = model * vec4(inPosition, 1.0);
    worldPos = wp.xyz;
    worldNormal = mat3(normalMatrix) * inNormal;
    uv = inUv;
    gl_Position = captureViewProj * wp;
}
