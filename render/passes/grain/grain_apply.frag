#version 450 core
#include "common.glsl"
// The camera's vignetting and noise on the composite (passes/grain/GrainPass.h), per camera
// pixel. Virtual pixels (coverage 1) are multiplied by V(r) = 1 + k1 r^2 + k2 r^4 (r from the
// principal point, 1 at the farthest corner); real pixels carry it through the footage. Then the
// noise: the footage's noise variance at the pixel's new value L (the noise-level function,
// per channel) minus what the pixel carries already: nothing on virtual pixels, (L / CI)^2 times
// the footage's at CI on real ones (the differential's L = CI + alpha dL is CI scaled where alpha
// = CI / L_r), so an unchanged pixel gets none. Gaussian, from a hash of pixel, channel and the
// frame's seed; correlated with the 4 neighbours' draws by beta when the footage's noise is.
in vec2 uv;
layout(binding = kUnitGrainComposite) uniform sampler2D composite;  // rgb linear, a = coverage
layout(binding = kUnitGrainCamera) uniform sampler2D cameraImage;   // sRGB8: samples linear
uniform int noiseOn, vignetteOn;
uniform vec3 noiseVariance[8];  // per level (sRGB-encoded value (i + 0.5) / 8), linear units^2
uniform float beta;             // neighbour weight of the correlated noise (0: white)
uniform uint seed;              // the frame's
uniform vec2 vignetteK;         // k1, k2
uniform vec2 principalPoint;    // camera pixels (OpenCV: x right, y down, top row 0)
uniform float invCornerR2;      // 1 / squared distance to the farthest corner
layout(location = 0) out vec4 outLinear;  // rgb linear, a = coverage (unchanged)
layout(location = 1) out vec4 outSrgb;    // through GL_FRAMEBUFFER_SRGB

float encodeSrgb(float v) {
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

vec3 varianceAt(vec3 v) {
    vec3 out3;
    for (int c = 0; c < 3; ++c) {
        float s = encodeSrgb(clamp(v[c], 0.0, 1.0)) * 8.0 - 0.5;
        int i0 = clamp(int(floor(s)), 0, 7);
        int i1 = min(i0 + 1, 7);
        float t = clamp(s - float(i0), 0.0, 1.0);
        out3[c] = mix(noiseVariance[i0][c], noiseVariance[i1][c], t);
    }
    return out3;
}

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

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 c = texelFetch(composite, px, 0);
    vec3 value = c.rgb;
    bool virtualPx = c.a > 0.75;
    if (vignetteOn != 0 && virtualPx) {
        vec2 d = vec2(px) - principalPoint;
        float r2 = dot(d, d) * invCornerR2;
        value *= max(1.0 + vignetteK.x * r2 + vignetteK.y * r2 * r2, 0.0);
    }
    if (noiseOn != 0) {
        vec3 need = varianceAt(value);
        if (!virtualPx) {
            vec3 ci = texelFetch(cameraImage, px, 0).rgb;
            vec3 k = value / max(ci, vec3(1e-4));
            need -= k * k * varianceAt(ci);
        }
        vec3 n = whiteNoise(px);
        if (beta > 0.0)
            n = (n + beta * (whiteNoise(px + ivec2(1, 0)) + whiteNoise(px - ivec2(1, 0)) +
                             whiteNoise(px + ivec2(0, 1)) + whiteNoise(px - ivec2(0, 1)))) /
                sqrt(1.0 + 4.0 * beta * beta);
        value = max(value + sqrt(max(need, vec3(0.0))) * n, vec3(0.0));
    }
    outLinear = vec4(value, c.a);
    outSrgb = vec4(clamp(value, 0.0, 1.0), 1.0);
}
