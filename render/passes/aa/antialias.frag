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
// silhouette is found as the camera would show it; the search along the edge for its two ends
// turns a stair step into the ramp a box-filtered pixel would see. Only edges where geometry
// meets are filtered (a virtual pixel near, or a real proxy's outline): the light the
// differential changes inside a real surface (a shadow's edge) is filtered by its own lookups.
// Pixels where neither they nor their 4 neighbours were changed (|D| > changeEpsilon) are
// written with the composite's value unchanged: where the renderer changed nothing the footage
// stays bit for bit. Most pixels stop after the 5 reads of the contrast test (on llvmpipe every
// read counts).
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
bool changed(vec3 composite, vec3 camera) {
    vec3 d = abs(composite - camera);
    return max(d.r, max(d.g, d.b)) > changeEpsilon;
}

// The edge-directed offset (pixels, along one axis) of pixel px, whose luma and that of its 4
// neighbours are lM, lN (y - 1), lS, lW (x - 1), lE and span `range`.
vec2 edgeOffset(ivec2 px, ivec2 hi, vec2 rcpSize, float lM, float lN, float lS, float lW,
                float lE, float range) {
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
    // The pixel and its 4 neighbours: the filter reads no other pixel's contribution (its offset
    // runs along one axis, by at most 1 pixel).
    ivec2 q[5] = ivec2[](px, clamp(px + ivec2(0, -1), ivec2(0), hi),
                         clamp(px + ivec2(0, 1), ivec2(0), hi),
                         clamp(px + ivec2(-1, 0), ivec2(0), hi),
                         clamp(px + ivec2(1, 0), ivec2(0), hi));
    vec4 c[5];
    float l[5];
    for (int i = 0; i < 5; ++i) {
        c[i] = texelFetch(compositeImage, q[i], 0);
        l[i] = lumaOf(c[i].rgb);
    }
    outLinear = c[0];
    outSrgb = vec4(clamp(c[0].rgb, 0.0, 1.0), 1.0);
    float maxL = max(max(max(l[1], l[2]), max(l[3], l[4])), l[0]);
    float minL = min(min(min(l[1], l[2]), min(l[3], l[4])), l[0]);
    float range = maxL - minL;
    if (range < max(edgeThresholdMin, maxL * edgeThreshold)) return;  // no edge
    bool near = false;
    for (int i = 0; i < 5; ++i) near = near || changed(c[i].rgb, texelFetch(cameraImage, q[i], 0).rgb);
    if (!near) return;  // the footage's own edge: left as it is
    // Only where geometry meets: a virtual pixel among the five, or a real proxy's outline (the
    // coverage changes). Inside a real surface the renderer's edges are the differential's light
    // (shadows, caustics, bounced light), which their own lookups filter over the pixel (the
    // focused shadow maps: docs/realtime-renderer.md "Shadow edges"); filtering them again
    // widens an edge the reference's pixels antialias once.
    bool geometric = false;
    for (int i = 0; i < 5; ++i)
        geometric = geometric || c[i].a > 0.75 || abs(c[i].a - c[0].a) > 0.25;
    if (!geometric) return;
    vec2 rcpSize = 1.0 / vec2(size);
    vec2 offset = edgeOffset(px, hi, rcpSize, l[0], l[1], l[2], l[3], l[4], range);
    if (offset == vec2(0.0)) return;
    vec2 pos = (vec2(px) + 0.5 + offset) * rcpSize;
    vec3 delta = textureLod(compositeImage, pos, 0.0).rgb - textureLod(cameraImage, pos, 0.0).rgb;
    vec3 result = texelFetch(cameraImage, px, 0).rgb + delta;
    if (!allFinite(result)) return;
    result = max(result, vec3(0.0));
    outLinear = vec4(result, c[0].a);
    outSrgb = vec4(clamp(result, 0.0, 1.0), 1.0);
}
