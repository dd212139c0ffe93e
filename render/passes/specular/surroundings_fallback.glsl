// Stand-in for render/passes/impostor/trace.glsl (the `impostor` helper's reflected-scene
// impostors, see /work/specular-contract.md) with the same interface, used until that lands:
// every ray leaves the modelled scene, so reflected and refracted rays see the environment map.
#ifndef MIRAGE_SURROUNDINGS_GLSL
#define MIRAGE_SURROUNDINGS_GLSL
struct SurroundingHit {
    bool hit;         // false: the ray leaves the modelled scene (the consumer uses L_env)
    vec3 position;    // world, metres
    vec3 normal;      // world unit normal, facing the ray origin
    vec3 albedo;      // linear base colour
    float roughness;
    float metallic;
    vec3 emissive;    // linear emitted radiance
    int origin;       // ORIGIN_REAL or ORIGIN_VIRTUAL
};
SurroundingHit traceSurroundings(int specularSlot, vec3 rayOrigin, vec3 rayDir) {
    SurroundingHit h;
    h.hit = false;
    h.position = rayOrigin;
    h.normal = -rayDir;
    h.albedo = vec3(0.0);
    h.roughness = 1.0;
    h.metallic = 0.0;
    h.emissive = vec3(0.0);
    h.origin = ORIGIN_NONE;
    return h;
}
#endif
