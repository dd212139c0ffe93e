#version 450 core
#include "common.glsl"
#include "passes/grain/footage_noise.glsl"
// The camera's vignetting and noise on the composite (passes/grain/GrainPass.h), per camera
// pixel. Virtual pixels (coverage 1) are multiplied by V(r) = 1 + k1 r^2 + k2 r^4 (r from the
// principal point, 1 at the farthest corner), all but the footage they show (already filmed
// through the lens); real pixels carry it through the footage. Then the
// noise: the footage's noise variance at the pixel's new value L (the noise-level function,
// per channel) minus what the pixel carries already: nothing on virtual pixels, (L / CI)^2 times
// the footage's at CI on real ones (the differential's L = CI + alpha dL is CI scaled where alpha
// = CI / L_r), so an unchanged pixel gets none. The draw n is the footage's own grain where it
// can be measured (footageGrain): the camera pixel's residual from an edge-preserving 5x5 mean,
// in units of its standard deviation, so what is added carries the camera's noise texture
// (its spatial correlation, demosaicing, compression) and changes with every frame as the
// footage's does; otherwise Gaussian, from a hash of pixel, channel and the frame's seed,
// correlated with the 4 neighbours' draws by beta when the footage's noise is. With the
// footage's draw, the standard deviation is added, not the variance: n already sits in the
// pixel as k sigma(CI) n, and sigma(L) - k sigma(CI) makes it sigma(L) n.
in vec2 uv;
layout(binding = kUnitGrainComposite) uniform sampler2D composite;  // rgb linear, a = coverage
layout(binding = kUnitGrainFootageShare) uniform sampler2D footageShare;  // rgb: video in it
layout(binding = kUnitGrainCamera) uniform sampler2D cameraImage;   // sRGB8: samples linear
uniform int noiseOn, vignetteOn;
uniform int footageGrain;        // 1: n from the footage's residual (else synthesised)
uniform float beta;             // neighbour weight of the correlated noise (0: white)
uniform uint seed;              // the frame's
uniform vec2 vignetteK;         // k1, k2
uniform vec2 principalPoint;    // camera pixels (OpenCV: x right, y down, top row 0)
uniform float invCornerR2;      // 1 / squared distance to the farthest corner
layout(location = 0) out vec4 outLinear;  // rgb linear, a = coverage (unchanged)
layout(location = 1) out vec4 outSrgb;    // through GL_FRAMEBUFFER_SRGB

uvec3 pcg3d(uvec3 v) {  // Jarzynski & Olano 2020, "Hash functions for GPU rendering"
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v ^= v >> 16u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    return v;
}

// Three independent standard normal draws for pixel p (Box-Muller).
vec3 whiteNoise(ivec2 p) {
    uvec3 a = pcg3d(uvec3(uvec2(p), seed));
    uvec3 b = pcg3d(uvec3(uvec2(p), seed ^ 0x9E3779B9u));
    vec3 u1 = max(vec3(a) * (1.0 / 4294967296.0), vec3(1e-7));
    vec3 u2 = vec3(b) * (1.0 / 4294967296.0);
    return sqrt(-2.0 * log(u1)) * cos(6.28318530718 * u2);
}

// The footage's noise draw at camera pixel p, per channel, in standard deviations: the
// residual of CI from its noise-free estimate (footage_noise.glsl) over the residual's standard
// deviation. ok is false where the estimate is the centre alone (an edge or a clipped pixel on
// every side) or the pixel is clipped: no residual to measure there.
// varianceCi: noiseVarianceAt(ci).
vec3 footageDraw(ivec2 p, vec3 ci, vec3 varianceCi, out bvec3 ok) {
    vec3 spread;
    vec3 residual = ci - footageMean(cameraImage, p, ci, varianceCi, spread);
    // Clipped footage holds no noise to take (a dark object before a white wall needs its own).
    ok = bvec3(vec3(greaterThan(spread, vec3(0.05))) * vec3(greaterThan(ci, vec3(kNoiseBlack))) *
               vec3(lessThan(ci, vec3(kNoiseWhite))));
    vec3 sigma = sqrt(max(varianceCi, vec3(1e-12)));
    return clamp(residual / (sigma * sqrt(max(spread, vec3(0.05)))), vec3(-4.0), vec3(4.0));
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 c = texelFetch(composite, px, 0);
    vec3 value = c.rgb;
    bool virtualPx = c.a > 0.75;
    if (vignetteOn != 0 && virtualPx) {
        vec2 d = vec2(px) - principalPoint;
        float r2 = dot(d, d) * invCornerR2;
        // The footage a virtual pixel shows (through glass, in a mirror) was filmed through the
        // lens already, nearby on a glass object: only the rest is darkened.
        vec3 filmed = clamp(texelFetch(footageShare, px, 0).rgb, vec3(0.0), max(value, vec3(0.0)));
        value = filmed + (value - filmed) * max(1.0 + vignetteK.x * r2 + vignetteK.y * r2 * r2, 0.0);
    }
    vec3 ci = texelFetch(cameraImage, px, 0).rgb;
    // A real pixel the renderer left as the footage already carries the footage's noise: nothing
    // to add (need = carried below), so skip the draw (most of a frame outside the virtual
    // objects' influence; the draw's 5x5 mean is most of this pass's time).
    bool unchanged = !virtualPx && all(lessThanEqual(abs(value - ci), vec3(1e-6)));
    if (noiseOn != 0 && !unchanged) {
        // What the pixel carries of the footage's noise already, scaled by k = L / CI.
        vec3 k = virtualPx ? vec3(0.0) : value / max(ci, vec3(1e-4));
        vec3 n = whiteNoise(px);
        if (beta > 0.0)
            n = (n + beta * (whiteNoise(px + ivec2(1, 0)) + whiteNoise(px - ivec2(1, 0)) +
                             whiteNoise(px + ivec2(0, 1)) + whiteNoise(px - ivec2(0, 1)))) /
                sqrt(1.0 + 4.0 * beta * beta);
        vec3 need = noiseVarianceAt(value);
        vec3 varianceCi = noiseVarianceAt(ci);
        bvec3 own = bvec3(false);
        vec3 draw = footageGrain != 0 ? footageDraw(px, ci, varianceCi, own) : vec3(0.0);
        vec3 carriedVariance = k * k * varianceCi;
        for (int c = 0; c < 3; ++c) {
            float carried = carriedVariance[c];
            if (own[c])  // the same draw: standard deviations add
                value[c] += (sqrt(need[c]) - sqrt(carried)) * draw[c];
            else  // an independent draw: variances add
                value[c] += sqrt(max(need[c] - carried, 0.0)) * n[c];
        }
        value = max(value, vec3(0.0));
    }
    outLinear = vec4(value, c.a);
    outSrgb = vec4(clamp(value, 0.0, 1.0), 1.0);
}
