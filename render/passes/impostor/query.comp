#version 450 core
#include "common.glsl"
#include "trace.glsl"
// Offline ray queries against the impostors (ImpostorPass::trace: tests, accuracy benchmark).
// Runs outside a frame, so it may use storage bindings 4 and 5 that frame passes use otherwise.
layout(local_size_x = 64) in;
struct QueryRay {
    vec4 origin;     // xyz world (m), w = specular slot
    vec4 direction;  // xyz unit world
};
struct QueryHit {
    vec4 positionHit;     // xyz world (m), w = 1 hit / 0 miss
    vec4 normalOrigin;    // xyz unit normal facing the ray origin, w = origin
    vec4 albedoRough;     // rgb linear base colour, w = roughness
    vec4 emissiveMetal;   // rgb linear emitted radiance, w = metallic
};
layout(std430, binding = kBindingQueryRays) readonly buffer QueryRays { QueryRay rays[]; };
layout(std430, binding = kBindingQueryHits) writeonly buffer QueryHits { QueryHit hits[]; };
uniform int rayCount;
void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= rayCount) return;
    QueryRay r = rays[i];
    SurroundingHit h = traceSurroundings(int(r.origin.w + 0.5), r.origin.xyz, r.direction.xyz);
    QueryHit q;
    q.positionHit = vec4(h.position, h.hit ? 1.0 : 0.0);
    q.normalOrigin = vec4(h.normal, float(h.origin));
    q.albedoRough = vec4(h.albedo, h.roughness);
    q.emissiveMetal = vec4(h.emissive, h.metallic);
    hits[i] = q;
}
