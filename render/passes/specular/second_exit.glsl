#ifndef MIRAGE_SECOND_EXIT_GLSL
#define MIRAGE_SECOND_EXIT_GLSL
// The environment light a glass pixel receives along its refracted path's second exit
// (specular.glsl refractedSecondExit: the light the back face reflects inside leaves the object
// again elsewhere), added by the composite to each glass pixel's L_env after the rough pass has
// blurred L_env (the term is the pixel's own: on a sphere's rim its neighbours in the glass's
// image see far less of it). Include after specular.glsl.
#include "passes/specular/specular_tables.glsl"
uniform int secondExitOn;  // SpecularOptions::secondExit

// True when the ray from p along dir passes no real surface within `len` metres, by a march in
// the camera's view of the real surfaces (a sample more than 1 cm and less than 25 cm behind
// the real surface at its pixel is inside it). Beyond the canvas or `len` the environment map,
// the capture of the real surroundings, stands for what the ray meets.
bool secondExitEscapes(vec3 p, vec3 dir, float len, sampler2D realSurfaces) {
    const int kSteps = 8;
    for (int i = 1; i <= kSteps; ++i) {
        vec3 q = p + dir * (len * float(i) / float(kSteps));
        vec2 cp;
        if (!projectToCanvas(q, cp)) return true;
        ivec2 qi = ivec2(floor(cp + 0.5));
        if (any(lessThan(qi, ivec2(0))) || any(greaterThanEqual(qi, ivec2(canvas.xy))))
            return true;
        vec4 S = texelFetch(realSurfaces, qi, 0);
        if (int(S.w + 0.5) != ORIGIN_REAL) continue;
        float behind = length(q - cameraPos.xyz) - length(S.xyz - cameraPos.xyz);
        if (behind > 0.01 && behind < 0.25) return false;
    }
    return true;
}

// The second exit's environment light at canvas pixel px, whose sharp refraction has the weight
// w2 and the distance din inside (GBuf_refr's weight); the primary G-buffer (position, normal,
// emissive: a = slot + 1), the back faces and the real surfaces of the frame. A real surface in
// the way (by the march above, over ten radii of the object) takes it: not added (the footage
// there is not looked up).
vec3 secondExitEnvironment(ivec2 px, vec3 w2, float din, sampler2D envMap,
                           sampler2D frontPosition, sampler2D frontNormal, sampler2D frontSlot,
                           sampler2D backPosition, sampler2D backNormal,
                           sampler2D realSurfaces) {
    if (secondExitOn == 0 || all(lessThanEqual(w2, vec3(0.0)))) return vec3(0.0);
    int slot = int(texelFetch(frontSlot, px, 0).a + 0.5) - 1;
    if (slot < 0) return vec3(0.0);
    GpuSpecularDraw sd = specularDrawTable[slot];
    GpuMaterial m = specularMaterialTable[sd.material];
    if (!(m.transmission > 0.0)) return vec3(0.0);
    vec3 a = texelFetch(frontPosition, px, 0).xyz;
    vec3 n = texelFetch(frontNormal, px, 0).xyz;
    vec3 d = a - cameraPos.xyz;
    if (!(dot(d, d) > 1e-12) || !(dot(n, n) > 0.25)) return vec3(0.0);
    vec3 P3, T3, w3;
    if (!refractedSecondExit(a, normalize(n), normalize(d), din, w2, m, sd, slot, frontPosition,
                             frontNormal, frontSlot, backPosition, backNormal, P3, T3, w3))
        return vec3(0.0);
    if (!secondExitEscapes(P3, T3, 10.0 * sd.radius, realSurfaces)) return vec3(0.0);
    vec3 e = w3 * environmentRadiance(envMap, T3);
    return allFinite(e) ? e : vec3(0.0);
}

#endif
