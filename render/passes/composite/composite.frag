#version 450 core
#include "common.glsl"
// Differential rendering (Knecht 2013 Eqs. 1-2), one output pixel per camera pixel:
//   real or empty pixel:  L_final = CI + alpha * (L_rv - L_r),  alpha = CI / L_r per channel
//   virtual pixel:        L_final = L_rv
// CI is the camera frame, sRGB-encoded 8-bit, linearised by the sRGB texture format (the camera
// response is taken to be the sRGB curve). L_* are scaled by `exposure` into camera units first.
// Guard where L_r is near 0 (a black surface, or light only the virtual light reaches): alpha
// fades to 1 below exposure.z (the model's own radiometry is used) and is capped at exposure.y,
// and the result is clamped to >= 0 and finite. Lens distortion: the L buffers were rendered
// undistorted on the canvas; `remap` gives each camera pixel's canvas position.
in vec2 uv;
layout(binding = 0) uniform sampler2D cameraImage;  // sRGB8 texture: samples are linear
layout(binding = 1) uniform sampler2D lRv;           // canvas, linear
layout(binding = 2) uniform sampler2D lR;
layout(binding = 3) uniform sampler2D gPosition;     // canvas, w = origin
layout(binding = 4) uniform sampler2D remap;         // camera size: canvas pixel (OpenCV conv.)
layout(location = 0) out vec4 outLinear;  // rgb linear; a = 0 empty, 0.5 real, 1 virtual
layout(location = 1) out vec4 outSrgb;    // written through GL_FRAMEBUFFER_SRGB: encoded sRGB8

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 ci = texelFetch(cameraImage, px, 0).rgb;
    vec2 canvasPx = texelFetch(remap, px, 0).xy;
    vec3 result = ci;
    float coverage = 0.0;
    if (canvasPx.x > -1000.0) {
        vec2 cuv = (canvasPx + 0.5) * canvas.zw;
        int origin = int(texelFetch(gPosition, ivec2(floor(canvasPx + 0.5)), 0).w + 0.5);
        vec3 rv = max(texture(lRv, cuv).rgb, vec3(0.0)) * exposure.x;
        vec3 r = max(texture(lR, cuv).rgb, vec3(0.0)) * exposure.x;
        if (origin == ORIGIN_VIRTUAL) {
            result = rv;
            coverage = 1.0;
        } else {
            vec3 t = smoothstep(vec3(0.0), vec3(exposure.z), r);
            vec3 ratio = min(ci / max(r, vec3(1e-6)), vec3(exposure.y));
            vec3 alpha = mix(vec3(1.0), ratio, t);
            result = ci + alpha * (rv - r);
            coverage = origin == ORIGIN_REAL ? 0.5 : 0.0;
        }
    }
    if (!allFinite(result)) result = vec3(0.0);
    result = max(result, vec3(0.0));
    outLinear = vec4(result, coverage);
    outSrgb = vec4(clamp(result, 0.0, 1.0), 1.0);
}
