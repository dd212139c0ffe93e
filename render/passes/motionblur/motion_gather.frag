#version 450 core
#include "common.glsl"
// The reconstruction filter of McGuire et al. 2012 ("A reconstruction filter for plausible motion
// blur"), gathering along the neighbourhood's largest motion with the paper's depth-aware weights
// (a sample in front blurs over this pixel by its own motion, one behind is seen through this
// pixel's motion; two moving samples blend), applied to what the renderer changed only.
//
// The footage is already blurred by the camera: blurring the composite as a whole would blur the
// real world twice. The composite C at a pixel is footage F plus what the renderer added
// (CompositeFootage: F = CI on real pixels, 0 on virtual ones, the back-projected video CI_bp on a
// mirror or glass pixel). A sample Y contributes to pixel X
//     C(Y)                    when X and Y lie in different layers (an object's silhouette: the
//                             object smears over what is behind it, footage or not),
//     F(X) C(Y) / F(Y)        when both are real surfaces: the differential change is blurred,
//                             the footage of X is kept as the camera made it. The change is a
//                             ratio there (the composite's L = CI + alpha dL is CI times
//                             L_rv / L_r), so the footage's noise at X is scaled as the change
//                             scales the light; a difference would move Y's noise into X and keep
//                             X's full noise in a shadow (where a darker pixel has less). Where
//                             F(Y) is nearly black, the difference below stands in;
//     C(Y) - F(Y) + F(X)      inside a mirror or glass (its rendered light is blurred, the
//                             reflected video is not blurred again).
// So a pixel whose neighbourhood the renderer did not change keeps its footage exactly, and a
// still camera (no motion) leaves the composite unchanged.
layout(binding = kUnitMotionVelocity) uniform sampler2D velocity;    // rg half motion, b depth
layout(binding = kUnitMotionTiles) uniform sampler2D neighbourMax;   // per tile; b = changed
layout(binding = kUnitMotionComposite) uniform sampler2D composite;  // linear, a = coverage
layout(binding = kUnitMotionFootage) uniform sampler2D footage;      // rgb footage, a = layer
uniform int tileSize;
uniform int samples;
uniform float softDepthExtent;  // metres
layout(location = 0) out vec4 outLinear;  // rgb linear, a = coverage (as the composite)
layout(location = 1) out vec4 outSrgb;    // through GL_FRAMEBUFFER_SRGB

// 1 when the sample at depth zb lies in front of (or level with) the one at za, fading to 0 over
// softDepthExtent behind it (the paper's softDepthCompare, depths positive).
float inFront(float za, float zb) {
    return clamp(1.0 - (zb - za) / softDepthExtent, 0.0, 1.0);
}
float cone(float distance, float halfLength) {
    return clamp(1.0 - distance / halfLength, 0.0, 1.0);
}
float cylinder(float distance, float halfLength) {
    return 1.0 - smoothstep(0.95 * halfLength, 1.05 * halfLength, distance);
}

// Footage (linear) below which a real pixel's change is blurred as a difference: the ratio's
// noise would grow without bound towards black.
const float kRatioFloor = 0.02;

void write(vec4 c) {
    outLinear = c;
    outSrgb = vec4(clamp(c.rgb, 0.0, 1.0), 1.0);
}

void main() {
    ivec2 X = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(composite, 0);
    vec4 cX = texelFetch(composite, X, 0);
    vec4 nMax = texelFetch(neighbourMax, X / tileSize, 0);
    float nLength = length(nMax.xy);
    // No motion worth a pixel, or nothing the renderer changed within reach: as composited.
    if (nLength <= 0.5 || nMax.z < 0.5) {
        write(cX);
        return;
    }
    vec4 vX4 = texelFetch(velocity, X, 0);
    vec4 fX = texelFetch(footage, X, 0);
    float vXLength = max(length(vX4.xy), 0.5);
    float zX = vX4.z;
    float weight = 1.0 / vXLength;
    vec3 sum = cX.rgb * weight;
    // Jitter along the line so that the taps' banding turns into fine noise (deterministic:
    // interleaved gradient noise of the pixel, the same in every replay).
    float j = fract(52.9829189 * fract(dot(vec2(X), vec2(0.06711056, 0.00583715)))) - 0.5;
    int centre = (samples - 1) / 2;
    for (int i = 0; i < samples; ++i) {
        if (i == centre) continue;
        float t = mix(-1.0, 1.0, (float(i) + j + 1.0) / float(samples + 1));
        ivec2 Y = clamp(ivec2(floor(vec2(X) + 0.5 + nMax.xy * t)), ivec2(0), size - 1);
        vec4 vY4 = texelFetch(velocity, Y, 0);
        float vYLength = max(length(vY4.xy), 0.5);
        float distance = length(vec2(Y - X));
        float f = inFront(zX, vY4.z);  // Y in front of X
        float b = inFront(vY4.z, zX);  // X in front of Y
        float a = f * cone(distance, vYLength) + b * cone(distance, vXLength) +
                  cylinder(distance, vYLength) * cylinder(distance, vXLength) * 2.0;
        vec4 fY = texelFetch(footage, Y, 0);
        vec3 cY = texelFetch(composite, Y, 0).rgb;
        vec3 term = cY;
        if (abs(fY.a - fX.a) < 0.5) {
            term = cY - fY.rgb + fX.rgb;
            if (fX.a < 0.5) {  // real surfaces: the ratio where the footage is not black
                bvec3 lit = greaterThan(fY.rgb, vec3(kRatioFloor));
                term = mix(term, fX.rgb * cY / max(fY.rgb, vec3(kRatioFloor)), vec3(lit));
            }
        }
        weight += a;
        sum += a * term;
    }
    vec3 result = sum / weight;
    if (!allFinite(result)) result = cX.rgb;
    write(vec4(max(result, vec3(0.0)), cX.a));
}
