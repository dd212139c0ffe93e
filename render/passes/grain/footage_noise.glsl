#ifndef MIRAGE_FOOTAGE_NOISE_GLSL
#define MIRAGE_FOOTAGE_NOISE_GLSL
// The footage's noise (passes/grain/GrainPass.h): its level at a linear value, and a camera
// pixel's noise-free estimate and noise draw. Shared by the grain pass (which adds the noise to
// what the renderer changed) and the composite (which shows the footage through mirrors and
// glass without the noise of the pixel it came from: the grain adds this pixel's).

// Footage within half a code of black, or from sRGB code 250 up, is clipped: it shows no noise.
const float kNoiseBlack = 0.5 / 255.0 / 12.92;
const float kNoiseWhite = 0.9560;

uniform vec3 noiseVariance[8];  // per level (sRGB-encoded value (i + 0.5) / 8), linear units^2

float noiseEncodeSrgb(float v) {
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

// The footage's noise variance at linear value v, per channel, interpolated between levels.
vec3 noiseVarianceAt(vec3 v) {
    vec3 out3;
    for (int c = 0; c < 3; ++c) {
        float s = noiseEncodeSrgb(clamp(v[c], 0.0, 1.0)) * 8.0 - 0.5;
        int i0 = clamp(int(floor(s)), 0, 7);
        int i1 = min(i0 + 1, 7);
        float t = clamp(s - float(i0), 0.0, 1.0);
        out3[c] = mix(noiseVariance[i0][c], noiseVariance[i1][c], t);
    }
    return out3;
}

// Camera pixel p's noise-free estimate: a bilateral 5x5 mean of the footage, its range
// sigma twice the noise's at the pixel's value ci, so the footage's edges stay out of it (the
// footage's texture survives; its noise is averaged over the pixels like the centre).
// spread: the variance of ci minus that mean in units of the pixel's noise variance,
// (1 - w0)^2 + the other weights' squares (w normalised; w0 the centre's). Per channel.
// varianceCi: noiseVarianceAt(ci), which the callers need as well.
vec3 footageMean(sampler2D image, ivec2 p, vec3 ci, vec3 varianceCi, out vec3 spread) {
    ivec2 size = textureSize(image, 0);
    vec3 invTwoSigma = 0.5 / sqrt(max(varianceCi, vec3(1e-12)));
    vec3 wSum = vec3(0.0), wMean = vec3(0.0), w2 = vec3(0.0);
    for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
            vec3 cq = texelFetch(image, clamp(p + ivec2(dx, dy), ivec2(0), size - 1), 0).rgb;
            vec3 d = (cq - ci) * invTwoSigma;
            vec3 w = exp(-0.5 * d * d);
            wSum += w;
            wMean += w * cq;
            w2 += w * w;
        }
    vec3 w0 = 1.0 / wSum;
    spread = (1.0 - w0) * (1.0 - w0) + (w2 - 1.0) / (wSum * wSum);
    return wMean / wSum;
}

#endif
