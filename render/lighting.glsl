// Shading helpers shared by the lighting passes (and the specular passes to come): light
// distance and shadow lookups, the BRDF. Include after common.glsl. All radiance linear.
#ifndef MIRAGE_LIGHTING_GLSL
#define MIRAGE_LIGHTING_GLSL

// Distance stored in the shadow maps: Euclidean (m) for point/spot lights, along the light
// direction from the ortho frustum's eye (positionRange.xyz) for directional lights.
float lightDistance(int li, vec3 p) {
    if (int(lights[li].directionType.w) == LIGHT_DIRECTIONAL)
        return dot(p - lights[li].positionRange.xyz, lights[li].directionType.xyz);
    return length(p - lights[li].positionRange.xyz);
}

// Direction to the light (unit) and the incident irradiance on a surface facing it
// (W/m^2 before the cosine): I / d^2 with the spot cone and range window for point/spot lights.
void incidentLight(int li, vec3 p, out vec3 wi, out vec3 irradiance) {
    if (int(lights[li].directionType.w) == LIGHT_DIRECTIONAL) {
        wi = -lights[li].directionType.xyz;
        irradiance = lights[li].radiantIntensity.rgb;
        return;
    }
    vec3 d = lights[li].positionRange.xyz - p;
    float dist2 = max(dot(d, d), 1e-8);
    float dist = sqrt(dist2);
    wi = d / dist;
    irradiance = lights[li].radiantIntensity.rgb * spotAttenuation(li, -wi) *
                 rangeWindow(li, dist) / dist2;
}

// Fraction of the light reaching p (0..1) from one shadow atlas: the layer whose frustum holds
// p, 2x2 percentage-closer filtered. Bias grows with the texel footprint and the slope.
float shadowVisibility(sampler2DArray map, int li, vec3 p, float NdotL) {
    ivec4 sh = lights[li].shadow;
    if (sh.y == 0) return 1.0;
    for (int f = 0; f < sh.y; ++f) {
        vec4 c = lights[li].viewProj[f] * vec4(p, 1.0);
        if (c.w <= 0.0) continue;
        vec3 ndc = c.xyz / c.w;
        if (any(greaterThan(abs(ndc.xy), vec2(1.0)))) continue;
        float d = lightDistance(li, p);
        ivec2 size = textureSize(map, 0).xy;
        float tanOrExtent = lights[li].radiantIntensity.w;
        float extent = int(lights[li].directionType.w) == LIGHT_DIRECTIONAL ? 2.0 * tanOrExtent
                                                                            : 2.0 * tanOrExtent * d;
        float texel = extent / float(size.x);
        float bias = params.y + 1.5 * texel / max(NdotL, 0.2);
        vec2 t = (ndc.xy * 0.5 + 0.5) * vec2(size) - 0.5;
        ivec2 i0 = ivec2(floor(t));
        vec2 fr = t - vec2(i0);
        float v[4];
        for (int k = 0; k < 4; ++k) {
            ivec2 q = clamp(i0 + ivec2(k & 1, k >> 1), ivec2(0), size - 1);
            float stored = texelFetch(map, ivec3(q, sh.x + f), 0).r;
            v[k] = d - bias <= stored ? 1.0 : 0.0;
        }
        return mix(mix(v[0], v[1], fr.x), mix(v[2], v[3], fr.x), fr.y);
    }
    return 1.0;
}

// Lambert diffuse + GGX specular (Smith-Schlick G, Schlick F, F0 = 0.04 for dielectrics), glTF
// metallic-roughness. Returns BRDF * cos (the factor multiplying incident irradiance).
vec3 brdfCos(vec3 n, vec3 v, vec3 l, vec3 baseColor, float metallic, float roughness) {
    float NdotL = max(dot(n, l), 0.0);
    float NdotV = max(dot(n, v), 1e-4);
    if (NdotL <= 0.0) return vec3(0.0);
    vec3 h = normalize(l + v);
    float NdotH = max(dot(n, h), 0.0), VdotH = max(dot(v, h), 0.0);
    float a = max(roughness * roughness, 1e-3), a2 = a * a;
    float dd = NdotH * NdotH * (a2 - 1.0) + 1.0;
    float D = a2 / (PI * dd * dd);
    float k = a * 0.5;
    float G = (NdotL / (NdotL * (1.0 - k) + k)) * (NdotV / (NdotV * (1.0 - k) + k));
    vec3 F0 = mix(vec3(0.04), baseColor, metallic);
    vec3 F = F0 + (1.0 - F0) * pow(1.0 - VdotH, 5.0);
    vec3 spec = D * G * F / (4.0 * NdotL * NdotV);
    vec3 diffuse = (1.0 - F) * (1.0 - metallic) * baseColor / PI;
    return (diffuse + spec) * NdotL;
}

#endif
