#version 450 core
#include "common.glsl"
// Radiance SH9 of the equirectangular environment map (one small mip level), for the diffuse
// environment light (shIrradiance in common.glsl): the same quadrature as the CPU projection
// (GpuScene::projectEquirectToSH): texel (x, y) of a w x h level is the direction of its centre,
// weighted by its solid angle cos(lat) (pi / h) (2 pi / w); the sum of weights is normalised to
// exactly 4 pi so a constant map gives exact irradiance. Also the solid-angle fraction the camera
// saw (alpha = 1). One work group; each invocation sums a strided share, then a tree reduction.
layout(local_size_x = 128) in;
layout(binding = kUnitEnvShSource) uniform sampler2D envLevel;
// The EnvironmentBlock layout (gpu_types.glsl) as a storage block: same offsets in std430.
layout(std430, binding = kBindingEnvironment) writeonly buffer EnvironmentOut {
    vec4 outSH[9];
    float outRotation;
    float outSeenFraction;
    float outPad0;
    float outPad1;
};
uniform int level;

const int kSums = 29;  // 9 x rgb, solid angle, seen solid angle
shared float partial[kSums][128];

void main() {
    int t = int(gl_LocalInvocationID.x);
    ivec2 size = textureSize(envLevel, level);
    float acc[kSums];
    for (int k = 0; k < kSums; ++k) acc[k] = 0.0;
    int count = size.x * size.y;
    for (int i = t; i < count; i += 128) {
        int x = i % size.x, y = i / size.x;
        float lat = 0.5 * PI - PI * (float(y) + 0.5) / float(size.y);
        float phi = 2.0 * PI * (float(x) + 0.5) / float(size.x) - PI;
        vec3 d = vec3(cos(lat) * sin(phi), sin(lat), -cos(lat) * cos(phi));
        float dOmega = cos(lat) * (PI / float(size.y)) * (2.0 * PI / float(size.x));
        vec4 c = texelFetch(envLevel, ivec2(x, y), level);
        if (!allFinite(c.rgb)) continue;
        float b[9];
        b[0] = 0.282095;
        b[1] = 0.488603 * d.y;
        b[2] = 0.488603 * d.z;
        b[3] = 0.488603 * d.x;
        b[4] = 1.092548 * d.x * d.y;
        b[5] = 1.092548 * d.y * d.z;
        b[6] = 0.315392 * (3.0 * d.z * d.z - 1.0);
        b[7] = 1.092548 * d.x * d.z;
        b[8] = 0.546274 * (d.x * d.x - d.y * d.y);
        for (int k = 0; k < 9; ++k) {
            acc[3 * k + 0] += c.r * b[k] * dOmega;
            acc[3 * k + 1] += c.g * b[k] * dOmega;
            acc[3 * k + 2] += c.b * b[k] * dOmega;
        }
        acc[27] += dOmega;
        acc[28] += clamp(c.a, 0.0, 1.0) * dOmega;
    }
    for (int k = 0; k < kSums; ++k) partial[k][t] = acc[k];
    barrier();
    for (int stride = 64; stride > 0; stride >>= 1) {
        if (t < stride)
            for (int k = 0; k < kSums; ++k) partial[k][t] += partial[k][t + stride];
        barrier();
    }
    if (t == 0) {
        float weight = partial[27][0];
        float norm = weight > 0.0 ? 4.0 * PI / weight : 0.0;
        for (int k = 0; k < 9; ++k)
            outSH[k] = vec4(partial[3 * k][0], partial[3 * k + 1][0], partial[3 * k + 2][0], 0.0) * norm;
        outRotation = 0.0;
        outSeenFraction = weight > 0.0 ? partial[28][0] / weight : 0.0;
        outPad0 = 0.0;
        outPad1 = 0.0;
    }
}
