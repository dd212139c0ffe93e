#version 450 core
#include "common.glsl"
// Two uses (uniform `mode`):
//  mode 0 — back faces of the specular objects (Wyman 2005's first pass): only fragments whose
//           outward normal faces away from the camera are kept, the nearest of them wins the
//           depth test. Output: world position (m) + specular slot + 1, world OUTWARD unit normal.
//  mode 1 — the nearest REAL surface (real draws only), for depth validation of back-projected
//           points (Knecht 2013 Sec. 4.1.3): world position + ORIGIN_REAL.
uniform int mode;
uniform int specularSlot;
in vec3 worldPos;
in vec3 worldNormal;
in vec2 uv;
layout(location = 0) out vec4 outPosition;  // xyz world (m); w = slot + 1 (mode 0) / origin (1)
layout(location = 1) out vec4 outNormal;    // xyz world outward unit normal (mode 0)
void main() {
    vec3 n = normalize(worldNormal);
    if (!allFinite(n)) n = vec3(0.0, 1.0, 0.0);
    if (mode == 0) {
        if (dot(n, cameraPos.xyz - worldPos) > 0.0) discard;  // a front face
        outPosition = vec4(worldPos, float(specularSlot + 1));
    } else {
        outPosition = vec4(worldPos, float(ORIGIN_REAL));
    }
    outNormal = vec4(n, 0.0);
}
