#version 450 core
#include "common.glsl"
// The velocity buffer of the motion blur (render/passes/motionblur), one texel per camera pixel:
// how far the surface the pixel shows moves on the canvas while the shutter is open, from where
// the previous frame's camera saw the same world point (the G-buffer position; for pixels that
// show no surface, the direction of the ray, a point at infinity) to where this frame's camera
// sees it, scaled from the frame interval to the exposure. Canvas pixels: with lens distortion
// the camera image's local scale differs from the canvas's slightly; the motion is not corrected
// for it. Moved objects are not handled here: their pixels get the camera's motion only.
//
// Output: rg = half the motion over the exposure (McGuire et al. 2012's V), clamped to
// `maxHalfLength` pixels (a point that was behind the previous camera, or a non-finite value, gets
// no motion); b = the surface's depth along the camera axis (metres; 1e4 where there is none).
layout(binding = kUnitMotionPosition) uniform sampler2D gPosition;  // canvas: xyz world, w = origin
layout(binding = kUnitMotionRemap) uniform sampler2D remap;  // camera size: canvas pixel
uniform mat4 previousViewProj;  // the previous frame's world -> clip
uniform mat4 clipToPrevious;    // this frame's clip -> the previous frame's clip
uniform float exposureScale;    // shutter / (this frame's time - the previous frame's)
uniform float maxHalfLength;    // pixels
layout(location = 0) out vec4 outVelocity;

vec2 clipToCanvas(vec4 c) {
    return (c.xy / c.w * 0.5 + 0.5) * canvas.xy;
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
#ifdef MIRAGE_IDENTITY_REMAP
    vec2 canvasPx = vec2(px);
#else
    vec2 canvasPx = texelFetch(remap, px, 0).xy;
#endif
    vec2 halfMotion = vec2(0.0);
    float depth = 1e4;
    if (canvasPx.x > -1000.0) {
        ivec2 cpi = clamp(ivec2(floor(canvasPx + 0.5)), ivec2(0), ivec2(canvas.xy) - 1);
        vec4 P = texelFetch(gPosition, cpi, 0);
        vec2 here = canvasPx + 0.5;  // GL window coordinates of the pixel centre
        vec4 previous;
        if (int(P.w + 0.5) != ORIGIN_NONE) {
            vec4 current = viewProj * vec4(P.xyz, 1.0);
            previous = previousViewProj * vec4(P.xyz, 1.0);
            depth = (viewMatrix * vec4(P.xyz, 1.0)).z;
            if (current.w > 1e-6) here = clipToCanvas(current);
        } else {
            vec2 ndc = here * canvas.zw * 2.0 - 1.0;
            previous = clipToPrevious * vec4(ndc, 1.0, 1.0);  // on the far plane
        }
        if (previous.w > 1e-6) halfMotion = 0.5 * exposureScale * (here - clipToCanvas(previous));
    }
    if (any(isnan(halfMotion)) || any(isinf(halfMotion))) halfMotion = vec2(0.0);
    float len = length(halfMotion);
    if (!(len <= maxHalfLength)) halfMotion *= maxHalfLength / len;  // also catches overflow
    if (any(isnan(halfMotion))) halfMotion = vec2(0.0);
    outVelocity = vec4(halfMotion, depth, 1.0);
}
