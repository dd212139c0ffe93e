#ifndef MIRAGE_ROUGH_TRANSMISSION_GLSL
#define MIRAGE_ROUGH_TRANSMISSION_GLSL
// The punctual lights' light that rough glass lets through towards the eye (direct.frag's
// MIRAGE_ROUGH_HIGHLIGHT variant; docs/specular.md, "Rough light"). A smooth glass object passes a
// point light on only along delta paths the renderer cannot draw (its caustic); a rough one
// scatters it over the GGX lobes of its surfaces, so it glows where the light reaches its far
// side: light enters through the back face (as the eye sees it) and leaves through the front
// towards the eye, directly or after a reflection inside. The eye's sharp two-interface path
// (specular.glsl refractTwoInterfaces, then internalPathExit for the share the back face reflects
// inside) gives the surface points where that light enters, P2 and P3; at each, per light, the
// rough dielectric BTDF (Walter et al. 2007) from the light into the glass along the path,
//   f_t |cos_i| / eta^2 = |i.h| |o.h| (1 - F(i.h)) D(h) G(i, o) / (|o.n| (i.h + eta o.h)^2),
//   h = -(i + eta o) / |i + eta o|,
// with i towards the light, o back along the path inside the glass and n the outward normal,
// times the path's weight from the eye to that point ((1 - F1) and the back face's F2 for P3,
// baseColour^2, Beer-Lambert) and the light's shadow-map visibility there. The 1 / eta^2 is the
// radiance's change at the front face on the way out. Both the front and the back face are rough
// (as the reference's GGX dielectric), so the lobe at the entry point is widened to alpha sqrt(2)
// (the two faces' slope variances add). Light scattered inside more than once is left out.
// Include after lighting.glsl and specular.glsl.
#include "passes/specular/specular_tables.glsl"
layout(binding = kUnitDirectBackPosition) uniform sampler2D backPosition;  // xyz, w = slot + 1
layout(binding = kUnitDirectBackNormal) uniform sampler2D backNormal;      // outward
uniform int roughTransmissionOn;   // DirectOptions::roughTransmission (and back faces bound)
uniform int roughRefractionSteps;  // the sharp path's march steps (specular.refractionSteps)

// GGX normal distribution and the Smith Lambda of a direction at cos theta = c (width alpha).
float ggxDistribution(float cosH, float alpha) {
    float a2 = alpha * alpha;
    float c2 = cosH * cosH;
    float k = c2 * (a2 - 1.0) + 1.0;
    return a2 / (PI * k * k);
}

float ggxSmithLambda(float c, float alpha) {
    float c2 = clamp(c * c, 1e-8, 1.0);
    return 0.5 * (-1.0 + sqrt(1.0 + alpha * alpha * (1.0 - c2) / c2));
}

// f_t |cos_i| / eta^2 above: wi towards the light (outside), wo back along the path (inside),
// n the outward unit normal, eta the glass's ior; 0 where wi is not outside or wo not inside.
float roughTransmissionCos(vec3 wi, vec3 wo, vec3 n, float eta, float alpha) {
    float cosI = dot(wi, n), cosO = dot(wo, n);
    if (cosI <= 0.0 || cosO >= 0.0) return 0.0;
    vec3 h = -(wi + eta * wo);
    float len = length(h);
    if (!(len > 1e-6)) return 0.0;
    h /= len;
    if (dot(h, n) < 0.0) h = -h;
    float iH = dot(wi, h), oH = dot(wo, h);
    if (iH <= 0.0 || oH >= 0.0) return 0.0;  // the microfacet must see both sides as they are
    float F = fresnelDielectric(iH, eta);
    float G = 1.0 / (1.0 + ggxSmithLambda(cosI, alpha) + ggxSmithLambda(cosO, alpha));
    // |i.h + eta o.h| = len: h is (i + eta o) normalised.
    return iH * -oH * (1.0 - F) * ggxDistribution(dot(h, n), alpha) * G / (-cosO * len * len);
}

// The lights' light entering the glass at surface point x (outward normal n) towards wo, back
// along the eye's path, which carries it to the eye with `weight`: routed as the direct light
// (L_rv always, L_r for a real light on a real object). roughness: the glass's (alpha =
// roughness^2).
void addTransmittedLight(vec3 x, vec3 n, vec3 wo, vec3 weight, float eta, float roughness,
                         bool pReal, inout vec3 rv, inout vec3 r) {
    if (all(lessThanEqual(weight, vec3(0.0)))) return;
    float alpha = max(roughness * roughness, 2e-3) * sqrt(2.0);
    for (int li = 0; li < lightCount; ++li) {
        vec3 wi, E;
        incidentLight(li, x, wi, E);
        float cosL = dot(n, wi);
        if (cosL <= 0.0) continue;
        float f = roughTransmissionCos(wi, wo, n, eta, alpha);
        if (!(f > 0.0)) continue;
        vec3 c = weight * f * E;
        vec3 visAll, visReal;
#ifdef MIRAGE_GLASS_SHADOWS
        lightVisibility(shadowAll, shadowReal, glassAll, glassReal, li, x, cosL, visAll, visReal);
#else
        lightVisibility(shadowAll, shadowReal, li, x, cosL, visAll, visReal);
#endif
        rv += c * visAll;
        if (lights[li].isReal == 1 && pReal) r += c * visReal;
    }
}

// The pixel px's rough glass (front point p, outward normal n, roughness): the light entering at
// the sharp path's back-face exit P2 and at P3, where the share the back face reflects inside
// leaves. Adds to rv / r; nothing for mirrors, metals and opaque objects.
void roughGlassTransmission(ivec2 px, vec3 p, vec3 n, float roughness, bool pReal, inout vec3 rv,
                            inout vec3 r) {
    if (roughTransmissionOn == 0) return;
    int slot = int(texelFetch(gEmissive, px, 0).a + 0.5) - 1;
    if (slot < 0) return;
    GpuSpecularDraw sd = specularDrawTable[slot];
    GpuMaterial m = specularMaterialTable[sd.material];
    float transWeight = transmissionShare(m);
    float eta = max(m.ior, 1e-3);
    // Near index matching a facet's tilt hardly turns the light (by about (1 - 1/ior) x the
    // tilt): the lobe narrows to the smooth interface's delta, whose image of a point light is not
    // drawn (as for smooth glass), and its peak would overflow what a pixel holds. The term fades
    // out for |ior - 1| from 0.05 down to 0.01.
    float indexFade = smoothstep(0.01, 0.05, abs(eta - 1.0));
    if (!(transWeight > 0.0) || !(indexFade > 0.0)) return;
    vec3 d = p - cameraPos.xyz;
    if (!(dot(d, d) > 1e-12) || !(dot(n, n) > 0.25)) return;
    d = normalize(d);
    n = normalize(n);
    vec3 P2, T2, N2;
    float F1, F2, inside;
    if (!refractTwoInterfaces(p, n, d, slot, sd, eta, viewProj, cameraPos.xyz, canvas.xy,
                              backPosition, backNormal, roughRefractionSteps, P2, T2, F1, F2,
                              inside, N2))
        return;
    vec3 T1 = normalize(refract(d, n, 1.0 / eta));
    vec3 base = clamp(m.baseColor.rgb, 0.0, 1.0);
    // The entry's (1 - F) is in the BTDF.
    vec3 toP2 = indexFade * transWeight * (1.0 - F1) * base * base;
    if (m.attenuationDistance > 0.0)
        toP2 *= pow(max(m.attenuationColor, vec3(1e-6)), vec3(inside / m.attenuationDistance));
    vec3 tRv = vec3(0.0), tR = vec3(0.0);
    addTransmittedLight(P2, N2, -T1, toP2, eta, roughness, pReal, tRv, tR);
    // The share the back face reflects inside, to where it meets the surface again.
    float F2in = fresnelDielectric(-dot(T1, N2), eta);  // 1 under total internal reflection
    vec3 T1r = reflect(T1, N2);
    vec3 P3, N3;
    if (F2in > 1e-4 && internalPathExit(P2, T1r, slot, sd, gPosition, gNormal, gEmissive,
                                         backPosition, backNormal, P3, N3)) {
        vec3 toP3 = toP2 * F2in;
        if (m.attenuationDistance > 0.0)
            toP3 *= pow(max(m.attenuationColor, vec3(1e-6)),
                        vec3(length(P3 - P2) / m.attenuationDistance));
        addTransmittedLight(P3, N3, -T1r, toP3, eta, roughness, pReal, tRv, tR);
    }
    // Within the half-float targets' range (a light almost straight behind a near-focus).
    rv += min(tRv, vec3(6.0e4));
    r += min(tR, vec3(6.0e4));
}

#endif
