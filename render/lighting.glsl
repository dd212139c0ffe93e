// Shading helpers shared by the lighting passes (and the specular passes to come): light
// distance and shadow lookups, the BRDF. Include after common.glsl. All radiance linear.
#ifndef MIRAGE_LIGHTING_GLSL
#define MIRAGE_LIGHTING_GLSL

// Distance stored in the shadow maps: Euclidean (m) for point/spot lights, along the light
// direction from the ortho frustum's eye (position) for directional lights.
float lightDistance(int li, vec3 p) {
    if (lights[li].type == LIGHT_DIRECTIONAL)
        return dot(p - lights[li].position, lights[li].direction);
    return length(p - lights[li].position);
}

// Direction to the light (unit) and the incident irradiance on a surface facing it
// (W/m^2 before the cosine): I / d^2 with the spot cone and range window for point/spot lights.
void incidentLight(int li, vec3 p, out vec3 wi, out vec3 irradiance) {
    if (lights[li].type == LIGHT_DIRECTIONAL) {
        wi = -lights[li].direction;
        irradiance = lights[li].radiantIntensity;
        return;
    }
    vec3 d = lights[li].position - p;
    float dist2 = max(dot(d, d), 1e-8);
    float dist = sqrt(dist2);
    wi = d / dist;
    irradiance = lights[li].radiantIntensity * spotAttenuation(li, -wi) *
                 rangeWindow(li, dist) / dist2;
}

// Fraction of the light reaching p (0..1) in the all-occluder shadow atlas (x) and, when
// `withReal`, in the real-occluder one (y; else y = x): the layer whose frustum holds p, 2x2
// percentage-closer filtered. Bias grows with the texel footprint and the slope. The layer search
// and footprint are shared and each atlas is read with one textureGather: on llvmpipe every
// texel read is costly and both sides of a branch run, so this is ~2x cheaper than two lookups.
#ifndef MIRAGE_MAX_SHADOW_FACES  // GpuScene::lightingDefines() sets it for the scene's lights
#define MIRAGE_MAX_SHADOW_FACES 6  // the most a light has: a point light's cube
#endif
vec2 shadowVisibility(sampler2DArray allMap, sampler2DArray realMap, int li, vec3 p, float NdotL,
                      bool withReal) {
    int firstLayer = lights[li].firstShadowLayer, layers = lights[li].shadowLayers;
    int layer = -1;
    vec2 t = vec2(0.0);
    // A constant bound (faces past `layers` masked off) lets the compiler unroll the loop and
    // read viewProj[f] at constant offsets; looping to `layers` made llvmpipe's direct pass 1.6x
    // slower.
    for (int f = 0; f < MIRAGE_MAX_SHADOW_FACES; ++f) {
        vec4 c = lights[li].viewProj[f] * vec4(p, 1.0);
        vec2 ndc = c.xy / c.w;
        if (f < layers && layer < 0 && c.w > 0.0 && all(lessThanEqual(abs(ndc), vec2(1.0)))) {
            layer = firstLayer + f;
            t = ndc * 0.5 + 0.5;
        }
    }
    if (layer < 0) return vec2(1.0);
    float d = lightDistance(li, p);
    vec2 size = vec2(textureSize(allMap, 0).xy);
    float tanOrExtent = lights[li].frustumSize;
    float extent = lights[li].type == LIGHT_DIRECTIONAL ? 2.0 * tanOrExtent
                                                                        : 2.0 * tanOrExtent * d;
    float bias = shadowBias + 1.5 * extent / size.x / max(NdotL, 0.2);
    // The gather footprint at t is texels floor(t * size - 0.5) + {0, 1}^2: w = (0,0), z = (1,0),
    // x = (0,1), y = (1,1); clamp-to-edge at the borders.
    vec2 fr = fract(t * size - 0.5);
    vec4 a = step(vec4(d - bias), textureGather(allMap, vec3(t, float(layer)), 0));
    float visAll = mix(mix(a.w, a.z, fr.x), mix(a.x, a.y, fr.x), fr.y);
    if (!withReal) return vec2(visAll);
    vec4 r = step(vec4(d - bias), textureGather(realMap, vec3(t, float(layer)), 0));
    return vec2(visAll, mix(mix(r.w, r.z, fr.x), mix(r.x, r.y, fr.x), fr.y));
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
