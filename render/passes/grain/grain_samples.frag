#version 450 core
#include "common.glsl"
// One sample block of the noise and vignetting estimates per output pixel
// (passes/grain/GrainPass.h). A block is usable under the exposure pass's rules
// (exposure_samples.frag): all its taps show an unhidden REAL surface that is not a mirror or
// glass, seen by a camera pixel whose footage is clipped neither at black nor near white, and
// L_r is smooth over it (max / min luminance within maxVariation). The footage of such a block is
// s L_r (s: the block's footage / L_r, per channel) plus noise: the residual
// e = CI - s L_r at each tap and at the camera pixel to its right is the noise.
// Output: mean footage (a = 1 usable), mean L_r, and the residual's unbiased variance per channel
// with the neighbouring residuals' correlation (a; + 1 / n for the bias of the block's mean), and
// the block's mean world position (the vignetting fit's tie between frames).
in vec2 uv;
layout(binding = kUnitGrainCamera) uniform sampler2D cameraImage;  // sRGB8: samples linear
layout(binding = kUnitGrainLR) uniform sampler2D lR;               // canvas, linear
layout(binding = kUnitGrainCausticR) uniform sampler2D causticR;   // canvas, linear
layout(binding = kUnitGrainPosition) uniform sampler2D gPosition;  // canvas, w = origin
layout(binding = kUnitGrainEmissive) uniform sampler2D gEmissive;  // canvas, a = slot + 1
layout(binding = kUnitGrainCanvasToCamera) uniform sampler2D canvasToCamera;  // camera pixel
uniform int blockSize;       // canvas pixels per side of a block
uniform int taps;            // taps per side (at most 4)
uniform int stride;          // canvas pixels between taps
uniform int withCaustics;    // 1: the caustic pass ran
uniform float maxVariation;  // of L_r's luminance over the block
layout(location = 0) out vec4 outFootage;   // rgb mean footage (linear), a = 1 usable block
layout(location = 1) out vec4 outRendered;  // rgb mean L_r (linear)
layout(location = 2) out vec4 outNoise;     // rgb residual variance, a = neighbour correlation
layout(location = 3) out vec4 outPosition;  // xyz mean world position of the taps (m), a = 1

const float kBlackLinear = 0.5 / 255.0 / 12.92;  // below half a code: clipped at black
const float kWhiteLinear = 0.9560;               // sRGB code 250: clipping near

float lum(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

// The footage and L_r at canvas pixel p; false where the block cannot use it.
bool tapAt(ivec2 p, ivec2 size, ivec2 camSize, ivec2 cameraOffset, out vec3 ci, out vec3 r) {
    ci = vec3(0.0);
    r = vec3(0.0);
    if (any(greaterThanEqual(p, size))) return false;
    int origin = int(texelFetch(gPosition, p, 0).w + 0.5);
    bool specular = texelFetch(gEmissive, p, 0).a > 0.5;
    vec2 q = texelFetch(canvasToCamera, p, 0).xy;
    ivec2 qi = ivec2(floor(q + 0.5)) + cameraOffset;
    if (origin != ORIGIN_REAL || specular || q.x < -1000.0 || any(lessThan(qi, ivec2(0))) ||
        any(greaterThanEqual(qi, camSize)))
        return false;
    ci = texelFetch(cameraImage, qi, 0).rgb;  // both top row first (CameraProjection.h)
    r = texelFetch(lR, p, 0).rgb;
    if (withCaustics != 0) r += texelFetch(causticR, p, 0).rgb;
    return !(any(lessThanEqual(ci, vec3(kBlackLinear))) ||
             any(greaterThanEqual(ci, vec3(kWhiteLinear))) || !allFinite(r));
}

void main() {
    ivec2 block = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(lR, 0);
    ivec2 camSize = textureSize(cameraImage, 0);
    ivec2 first = block * blockSize + (blockSize - (taps - 1) * stride) / 2;
    vec3 ci[16], r[16], ciRight[16], rRight[16];
    bool right[16];
    vec3 sumCi = vec3(0.0), sumR = vec3(0.0), sumP = vec3(0.0);
    float minR = 1e30, maxR = 0.0;
    bool usable = true;
    int n = taps * taps;
    for (int k = 0; k < n && usable; ++k) {
        ivec2 p = first + ivec2(k % taps, k / taps) * stride;
        usable = tapAt(p, size, camSize, ivec2(0), ci[k], r[k]);
        // The camera pixel to the right, read at the canvas pixel to the right (the lens map is
        // locally a shift): noise correlation between neighbouring camera pixels.
        right[k] = usable && tapAt(p + ivec2(1, 0), size, camSize, ivec2(0), ciRight[k], rRight[k]);
        float l = lum(r[k]);
        minR = min(minR, l);
        maxR = max(maxR, l);
        sumCi += ci[k];
        sumR += r[k];
        sumP += texelFetch(gPosition, min(p, size - 1), 0).xyz;
    }
    usable = usable && minR > 0.0 && maxR <= maxVariation * minR;
    vec3 meanCi = sumCi / float(n), meanR = sumR / float(n);
    outFootage = vec4(meanCi, usable ? 1.0 : 0.0);
    outRendered = vec4(meanR, 0.0);
    outPosition = vec4(sumP / float(n), 1.0);
    if (!usable) {
        outNoise = vec4(0.0);
        return;
    }
    vec3 s = meanCi / max(meanR, vec3(1e-12));  // the block's footage per unit L_r
    vec3 sumE = vec3(0.0), sumE2 = vec3(0.0);
    for (int k = 0; k < n; ++k) {
        vec3 e = ci[k] - s * r[k];
        sumE += e;
        sumE2 += e * e;
    }
    vec3 meanE = sumE / float(n);
    vec3 variance = max(sumE2 - float(n) * meanE * meanE, vec3(0.0)) / float(n - 1);
    float cov = 0.0, pairs = 0.0;
    for (int k = 0; k < n; ++k) {
        if (!right[k]) continue;
        vec3 a = ci[k] - s * r[k] - meanE, b = ciRight[k] - s * rRight[k] - meanE;
        cov += dot(a, b);
        pairs += 1.0;
    }
    float total = variance.r + variance.g + variance.b;
    float correlation = pairs > 1.0 && total > 0.0 ? cov / pairs / total + 1.0 / float(n) : 0.0;
    outNoise = vec4(variance, correlation);
}
