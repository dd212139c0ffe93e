#version 450 core
#include "common.glsl"
// Anti-aliasing of what the renderer adds to the footage (docs/camera-matching.md,
// "Anti-aliasing"). The composite is the footage CI plus the renderer's contribution
//   D = L_final - CI   (the differential term on real pixels, L_rv - CI on virtual ones),
// so filtering D alone leaves the footage, which the camera's optics already anti-aliased,
// untouched: L_aa(p) = CI(p) + D(p + o), with o the edge-directed offset of a morphological
// filter (after Lottes' FXAA 3.11, quality variant) and D read bilinearly, i.e. the share of
// the neighbour across the edge that its coverage would give. Edges are found on the
// composite's perceptual luma (sqrt of linear luminance, clamped to 0..1), so a virtual
// silhouette and a shadow's edge are found as the camera would show them; the search along the
// edge for its two ends turns a stair step into the ramp a box-filtered pixel would see.
// Pixels with no changed pixel (|D| > changeEpsilon) in their 3x3 neighbourhood are written
// with the composite's value unchanged: where the renderer changed nothing the footage stays
// bit for bit.
in vec2 uv;
layout(binding = kUnitAntialiasComposite) uniform sampler2D compositeImage;  // linear, a = coverage
layout(binding = kUnitAntialiasCamera) uniform sampler2D cameraImage;       // sRGB8, samples linear
uniform float edgeThreshold;     // relative to the local maximum of the luma
uniform float edgeThresholdMin;  // absolute floor (luma 0..1)
uniform float subpixel;          // share of the 3x3 blur for single-pixel features
uniform float changeEpsilon;     // linear camera units
uniform int searchSteps;         // 1..12
layout(location = 0) out vec4 outLinear;  // rgb linear; a = the composite's coverage
layout(location = 1) out vec4 outSrgb;    // written through GL_FRAMEBUFFER_SRGB

const vec3 kLumaWeights = vec3(0.2126, 0.7152, 0.0722);  // Rec. 709, linear
// Pixels per step of the search along an edge (FXAA's quality preset 39 spacing).
const float kSearchStep[12] = float[](1.0, 1.0, 1.0, 1.0, 1.0, 1.5, 2.0, 2.0, 2.0, 2.0, 4.0, 8.0);

float lumaOf(vec3 linearRgb) {
    return sqrt(clamp(dot(linearRgb, kLumaWeights), 0.0, 1.0));
}
float lumaAt(ivec2 p) {
    return lumaOf(texelFetch(compositeImage, p, 0).rgb);
}
// At a position in pixels (pixel centres at +0.5), bilinear.
float lumaAtPos(vec2 pos, vec2 rcpSize) {
    return lumaOf(textureLod(compositeImage, pos * rcpSize, 0.0).rgb);
}
bool changedAt(ivec2 p) {
    vec3 d = abs(texelFetch(compositeImage, p, 0).rgb - texelFetch(cameraImage, p, 0).rgb);
    return max(d.r, max(d.g, d.b)) > changeEpsilon;
}

// The edge-directed offset (pixels, along `across`) of pixel px; 0 where no edge is found.
vec2 edgeOffset(ivec2 px, ivec2 hi, vec2 rcpSize) {
    float lM = lumaAt(px);
    float lN = lumaAt(clamp(px + ivec2(0, -1), ivec2(0), hi));
    float lS = lumaAt(clamp(px + ivec2(0, 1), ivec2(0), hi));
    float lW = lumaAt(clamp(px + ivec2(-1, 0), ivec2(0), hi));
    float lE = lumaAt(clamp(px + ivec2(1, 0), ivec2(0), hi));
    float maxL = max(max(max(lN, lS), max(lW, lE)), lM);
    float minL = min(min(min(lN, lS), min(lW, lE)), lM);
    float range = maxL - minL;
    if (range < max(edgeThresholdMin, maxL * edgeThreshold)) return vec2(0.0);
    float lNW = lumaAt(clamp(px + ivec2(-1, -1), ivec2(0), hi));
    float lNE = lumaAt(clamp(px + ivec2(1, -1), ivec2(0), hi));
    float lSW = lumaAt(clamp(px + ivec2(-1, 1), ivec2(0), hi));
    float lSE = lumaAt(clamp(px + ivec2(1, 1), ivec2(0), hi));

    // Single-pixel features: how far the pixel stands out of its 3x3 low-pass.
    float lowPass = (2.0 * (lN + lS + lW + lE) + lNW + lNE + lSW + lSE) / 12.0;
    float sub = smoothstep(0.0, 1.0, clamp(abs(lowPass - lM) / range, 0.0, 1.0));
    float subpixelOffset = sub * sub * subpixel;

    // Horizontal edge (luma changes along y) or vertical one.
    float edgeH = abs(lN + lS - 2.0 * lM) * 2.0 + abs(lNW + lSW - 2.0 * lW) +
                  abs(lNE + lSE - 2.0 * lE);
    float edgeV = abs(lW + lE - 2.0 * lM) * 2.0 + abs(lNW + lNE - 2.0 * lN) +
                  abs(lSW + lSE - 2.0 * lS);
    bool horizontal = edgeH >= edgeV;
    float l1 = horizontal ? lN : lW;  // the negative side across the edge
    float l2 = horizontal ? lS : lE;  // the positive side
    float g1 = l1 - lM, g2 = l2 - lM;
    bool negativeSide = abs(g1) >= abs(g2);
    float gradientScaled = 0.25 * max(abs(g1), abs(g2));
    float stepAcross = negativeSide ? -1.0 : 1.0;
    float edgeLuma = 0.5 * (lM + (negativeSide ? l1 : l2));  // the luma on the edge itself

    // Walk along the edge (half a pixel across, on it) until the luma leaves the edge's.
    vec2 along = horizontal ? vec2(1.0, 0.0) : vec2(0.0, 1.0);
    vec2 acrossDir = horizontal ? vec2(0.0, 1.0) : vec2(1.0, 0.0);
    vec2 start = vec2(px) + 0.5 + acrossDir * (0.5 * stepAcross);
    vec2 p1 = start - along, p2 = start + along;
    float e1 = lumaAtPos(p1, rcpSize) - edgeLuma, e2 = lumaAtPos(p2, rcpSize) - edgeLuma;
    bool done1 = abs(e1) >= gradientScaled, done2 = abs(e2) >= gradientScaled;
    for (int i = 1; i < searchSteps && !(done1 && done2); ++i) {
        if (!done1) {
            p1 -= along * kSearchStep[i];
            e1 = lumaAtPos(p1, rcpSize) - edgeLuma;
            done1 = abs(e1) >= gradientScaled;
        }
        if (!done2) {
            p2 += along * kSearchStep[i];
            e2 = lumaAtPos(p2, rcpSize) - edgeLuma;
            done2 = abs(e2) >= gradientScaled;
        }
    }
    float d1 = dot(start - p1, along), d2 = dot(p2 - start, along);
    bool toEnd1 = d1 < d2;
    float dist = min(d1, d2), span = d1 + d2;
    // The blend is right only if the nearer end turns the luma the way the pixel leans.
    bool lumaBelow = lM - edgeLuma < 0.0;
    bool goodSpan = ((toEnd1 ? e1 : e2) < 0.0) != lumaBelow;
    float edgeBlend = goodSpan ? 0.5 - dist / span : 0.0;
    float blend = max(edgeBlend, subpixelOffset);
    return acrossDir * (blend * stepAcross);
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(compositeImage, 0);
    ivec2 hi = size - 1;
    vec4 here = texelFetch(compositeImage, px, 0);
    outLinear = here;
    outSrgb = vec4(clamp(here.rgb, 0.0, 1.0), 1.0);
    bool near = false;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
            near = near || changedAt(clamp(px + ivec2(dx, dy), ivec2(0), hi));
    if (!near) return;
    vec2 rcpSize = 1.0 / vec2(size);
    vec2 offset = edgeOffset(px, hi, rcpSize);
    if (offset == vec2(0.0)) return;
    vec2 pos = (vec2(px) + 0.5 + offset) * rcpSize;
    vec3 delta = textureLod(compositeImage, pos, 0.0).rgb - textureLod(cameraImage, pos, 0.0).rgb;
    vec3 result = texelFetch(cameraImage, px, 0).rgb + delta;
    if (!allFinite(result)) return;
    result = max(result, vec3(0.0));
    outLinear = vec4(result, here.a);
    outSrgb = vec4(clamp(result, 0.0, 1.0), 1.0);
}
