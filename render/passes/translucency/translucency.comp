#version 450 core
#include "common.glsl"
#include "lighting.glsl"
#include "passes/translucency/translucency.glsl"
// The voxel number map at run time (Mochida et al.; docs/translucency.md), in two dispatches
// over the S surface voxels of one translucent object (objectIndex; its buffers' slices from
// translucentObjects[objectIndex].offsets):
//  stage 0: irradiance E_i = sum_lights F_t(cos) cos I vis + F_t-weighted environment
//           irradiance at every outer surface voxel i; for L_rv every light with visibility
//           through all occluders, for L_r only real lights with the real-only shadow maps and
//           a real environment (docs/realtime-renderer.md "Real and virtual: routing");
//  stage 1: per output voxel o, L_o = (1/pi) a_eff sum_i E_i A_i c_i e^{-k tau(i, o)}, the
//           radiance leaving o before the exit boundary's F_t (direct.frag applies it per pixel).
layout(local_size_x = 64) in;

const float kNearField = 2.01;  // VoxelNumberMap::kNearField (voxel edges)

// Per surface voxel (all objects' in order): (centre xyz world m, 0), (outward unit normal xyz,
// near-field scale g_o), (A_i c_i per channel if on the outer surface, else 0; 0).
struct TranslucentVoxel {
    vec4 position;
    vec4 normal;
    vec4 weight;
};
layout(std430, binding = kBindingTranslucentVoxels) readonly buffer Voxels {
    TranslucentVoxel voxels[];
};
layout(std430, binding = kBindingTranslucentIrradiance) buffer Irradiance { vec4 E[]; };
layout(std430, binding = kBindingTranslucentRadiance) writeonly buffer Radiance { vec4 L[]; };
layout(binding = kUnitTranslucencyShadowAll) uniform sampler2DArray shadowAll;
layout(binding = kUnitTranslucencyShadowReal) uniform sampler2DArray shadowReal;
#ifdef MIRAGE_GLASS_SHADOWS
layout(binding = kUnitTranslucencyGlassAll) uniform sampler2DArray glassAll;
layout(binding = kUnitTranslucencyGlassReal) uniform sampler2DArray glassReal;
#endif
uniform int stage;
uniform int objectIndex;

// Surface voxel i of the object (local number); v0 = its first voxel in the buffers.
void irradiance(int i, int S, int v0, TranslucentObjectGpu obj) {
    TranslucentVoxel v = voxels[v0 + i];
    vec3 rv = vec3(0.0), r = vec3(0.0);
    if (any(greaterThan(v.weight.rgb, vec3(0.0)))) {  // cavity walls receive no outside light
        vec3 p = v.position.xyz;
        vec3 N = v.normal.xyz;
        float ior = obj.params.x;
        // Visibility from just outside the voxel, along its normal (as the CPU code).
        vec3 x = p + N * obj.gridOrigin.w;
        for (int li = 0; li < lightCount; ++li) {
            vec3 wi, Ei;
            incidentLight(li, p, wi, Ei);
            float cosN = dot(N, wi);
            if (cosN <= 0.0) continue;
            vec3 visAll, visReal;
#ifdef MIRAGE_GLASS_SHADOWS
            lightVisibility(shadowAll, shadowReal, glassAll, glassReal, li, x, cosN, visAll,
                            visReal);
#else
            lightVisibility(shadowAll, shadowReal, li, x, cosN, visAll, visReal);
#endif
            vec3 c = boundaryTransmittance(ior, cosN) * cosN * Ei;
            rv += c * visAll;
            if (lights[li].isReal == 1) r += c * visReal;
        }
        if (envOrigin != 0) {
            vec3 e = obj.params.y * shIrradiance(N);
            rv += e;
            if (envOrigin == ORIGIN_REAL) r += e;
        }
    }
    E[2 * v0 + i] = vec4(allFinite(rv) ? rv : vec3(0.0), 0.0);
    E[2 * v0 + S + i] = vec4(allFinite(r) ? r : vec3(0.0), 0.0);
}

void scatter(int o, int S, int v0, TranslucentObjectGpu obj) {
    vec3 rv = vec3(0.0), r = vec3(0.0);
    int lutFirst = obj.offsets.z;
    vec3 falloff = obj.falloff.rgb;
    // The near field (centres within kNearField voxel edges of o's) is scaled by g_o
    // (VoxelNumberMap::kernelScales): no stripes where the grid cuts a face at an angle.
    vec3 po = voxels[v0 + o].position.xyz;
    float reach = kNearField * obj.gridOrigin.w;
    vec3 nearRv = vec3(0.0), nearR = vec3(0.0);
    for (int i = 0; i < S; ++i) {
        vec3 w = voxels[v0 + i].weight.rgb;
        if (w == vec3(0.0)) continue;
        vec3 k = w * exp(-falloff * translucentTau(i, o, S, lutFirst));
        if (distance(voxels[v0 + i].position.xyz, po) <= reach) {
            nearRv += E[2 * v0 + i].rgb * k;
            nearR += E[2 * v0 + S + i].rgb * k;
        } else {
            rv += E[2 * v0 + i].rgb * k;
            r += E[2 * v0 + S + i].rgb * k;
        }
    }
    float g = voxels[v0 + o].normal.w;
    L[2 * v0 + o] = vec4((rv + g * nearRv) * obj.albedoOverPi.rgb, 0.0);
    L[2 * v0 + S + o] = vec4((r + g * nearR) * obj.albedoOverPi.rgb, 0.0);
}

void main() {
    TranslucentObjectGpu obj = translucentObjects[objectIndex];
    int S = obj.gridDims.w;
    int v0 = obj.offsets.y;
    int i = int(gl_GlobalInvocationID.x);
    if (i >= S) return;
    if (stage == 0)
        irradiance(i, S, v0, obj);
    else
        scatter(i, S, v0, obj);
}
