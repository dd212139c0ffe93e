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

#ifndef MIRAGE_MAX_SHADOW_FACES  // GpuScene::lightingDefines() sets it for the scene's lights
#define MIRAGE_MAX_SHADOW_FACES 6  // the most a light has: a point light's cube
#endif
// The shadow layer whose frustum holds p: atlas layer, texture coordinate, light distance d,
// depth bias, and the bilinear weights of the 2x2 gather footprint. False outside every layer.
bool shadowFootprint(int li, vec3 p, float NdotL, float mapSize, out int layer, out vec2 t,
                     out float d, out float bias, out vec2 fr) {
    int firstLayer = lights[li].firstShadowLayer, layers = lights[li].shadowLayers;
    layer = -1;
    t = vec2(0.0);
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
    d = lightDistance(li, p);
    float tanOrExtent = lights[li].frustumSize;
    float extent = lights[li].type == LIGHT_DIRECTIONAL ? 2.0 * tanOrExtent
                                                        : 2.0 * tanOrExtent * d;
    // On a slope the receiver's depth changes by a texel's extent x tan(angle to the light) per
    // texel (at most extent / NdotL, which the bilinear lookup allows for, 1.5 texels' worth).
    // The PCF's taps reach 2 texels, but those carry at most 1/16 of the weight: 1.5 texels of
    // the exact slope, tan = sqrt(1 - NdotL^2) / NdotL, so that the bias shifts the shadow of an
    // occluder standing on the receiver (a box's base) no more than needed.
    float c = max(NdotL, 0.2);
#ifdef MIRAGE_SHADOW_PCF
    float slope = sqrt(1.0 - c * c) / c;
#else
    float slope = 1.0 / c;
#endif
    bias = shadowBias + 1.5 * extent / mapSize * slope;
    // The gather footprint at t is texels floor(t * size - 0.5) + {0, 1}^2: w = (0,0), z = (1,0),
    // x = (0,1), y = (1,1); clamp-to-edge at the borders.
    fr = fract(t * mapSize - 0.5);
    return layer >= 0;
}

float bilinearGather(vec4 g, vec2 fr) { return mix(mix(g.w, g.z, fr.x), mix(g.x, g.y, fr.x), fr.y); }

// A textureGather's four texels (x: (0,1), y: (1,1), z: (1,0), w: (0,0)) weighted by separable
// per-texel weights wx (columns 0, 1) and wy (rows 0, 1).
float weightedGather(vec4 g, vec2 wx, vec2 wy) {
    return dot(g, vec4(wx.x * wy.y, wx.y * wy.y, wx.y * wy.x, wx.x * wy.x));
}

// The hat (linear interpolation's kernel, support -1..1) integrated from -1 to v.
float hatIntegral(float v) {
    v = clamp(v, -1.0, 1.0);
    return v < 0.0 ? 0.5 * (v + 1.0) * (v + 1.0) : 1.0 - 0.5 * (1.0 - v) * (1.0 - v);
}

// Per-axis weights of the 4 texels at offsets -1 - fr, -fr, 1 - fr, 2 - fr from the lookup for
// a box of w texels (0 < w <= 2) convolved with the bilinear hat: the bilinear weights as w -> 0,
// shadowPcf's at w = 2 (they sum to 1).
vec4 boxHatWeights(float fr, float w) {
    vec4 x = vec4(-1.0, 0.0, 1.0, 2.0) - fr;
    float h = 0.5 * w;
    vec4 wt;
    for (int i = 0; i < 4; ++i) wt[i] = (hatIntegral(h - x[i]) - hatIntegral(-h - x[i])) / w;
    return wt;
}

// Percentage-closer filtering over the 4x4 texels around the lookup with per-axis weights wx, wy
// (texel columns and rows -1..2 of the bilinear footprint). Four textureGathers.
float shadowPcfWeighted(sampler2DArray map, vec3 tc, float ref, vec4 wx, vec4 wy) {
    vec4 lo = step(vec4(ref), textureGatherOffset(map, tc, ivec2(-1, -1), 0));
    vec4 rx = step(vec4(ref), textureGatherOffset(map, tc, ivec2(1, -1), 0));
    vec4 ry = step(vec4(ref), textureGatherOffset(map, tc, ivec2(-1, 1), 0));
    vec4 hi = step(vec4(ref), textureGatherOffset(map, tc, ivec2(1, 1), 0));
    return weightedGather(lo, wx.xy, wy.xy) + weightedGather(rx, wx.zw, wy.xy) +
           weightedGather(ry, wx.xy, wy.zw) + weightedGather(hi, wx.zw, wy.zw);
}

// Percentage-closer filtering over the 4x4 texels around the lookup (columns and rows -1..2 of
// the bilinear footprint, fr its fraction): the visibility averaged over a 2-texel box around t
// of the bilinearly interpolated depth test. Per axis the weights are that box convolved with
// the bilinear hat at offsets -1 - fr, -fr, 1 - fr, 2 - fr: (1 - fr)^2 / 4, 1/2 - fr^2 / 4,
// 1/2 - (1 - fr)^2 / 4, fr^2 / 4 (they sum to 1). Continuous in t with a continuous slope, so a
// straight occluder edge leaves a straight ramp about 2 texels wide instead of the bilinear
// lookup's 1-texel stair steps. Four textureGathers.
float shadowPcf(sampler2DArray map, vec3 tc, float ref, vec2 fr) {
    vec2 a = 1.0 - fr;
    vec2 w0 = 0.25 * a * a, w1 = 0.5 - 0.25 * fr * fr, w2 = 0.5 - 0.25 * a * a, w3 = 0.25 * fr * fr;
    return shadowPcfWeighted(map, tc, ref, vec4(w0.x, w1.x, w2.x, w3.x),
                             vec4(w0.y, w1.y, w2.y, w3.y));
}

// Fraction of the light reaching p (0..1) in the all-occluder shadow atlas (x) and, when
// `withReal`, in the real-occluder one (y; else y = x): the layer whose frustum holds p, 2x2
// bilinear or, with MIRAGE_SHADOW_PCF (GpuScene::setShadowPcf), 4x4 percentage-closer
// filtered. Bias grows with the texel footprint
// and the slope. The layer search and footprint are shared and each atlas is read with
// textureGather: on llvmpipe every texel read is costly, so this is ~2x cheaper than separate
// lookups.
vec2 shadowVisibilityAt(sampler2DArray allMap, sampler2DArray realMap, int layer, vec2 t, float d,
                        float bias, vec2 fr, bool withReal) {
#ifdef MIRAGE_SHADOW_PCF
    vec3 tc = vec3(t, float(layer));
    float pcfAll = shadowPcf(allMap, tc, d - bias, fr);
    return vec2(pcfAll, withReal ? shadowPcf(realMap, tc, d - bias, fr) : pcfAll);
#else
    vec4 a = step(vec4(d - bias), textureGather(allMap, vec3(t, float(layer)), 0));
    float visAll = bilinearGather(a, fr);
    if (!withReal) return vec2(visAll);
    vec4 r = step(vec4(d - bias), textureGather(realMap, vec3(t, float(layer)), 0));
    return vec2(visAll, bilinearGather(r, fr));
#endif
}

// The camera pixel's footprint on the surface through p with normal n (world metres per pixel
// along the image's x and y: where the neighbouring pixels' rays meet the tangent plane), for
// the focused maps' filter (focusedVirtualVisibility). A pass shading the camera's visible
// surfaces sets it per pixel (setShadowPixelFootprint); zero, the default, means none is known
// (a hit seen in a mirror, a photon, a point inside a volume).
vec3 shadowPixelDx = vec3(0.0), shadowPixelDy = vec3(0.0);

void setShadowPixelFootprint(vec3 p, vec3 n) {
    shadowPixelDx = shadowPixelDy = vec3(0.0);
#ifdef MIRAGE_SHADOW_NO_PIXEL_FOOTPRINT
    return;  // ShadowOptions::pixelFootprint off: the 2-texel PCF
#endif
    vec3 d = p - cameraPos.xyz;
    // The OpenCV camera's axes in world space: the view matrix's rows.
    vec3 right = vec3(viewMatrix[0][0], viewMatrix[1][0], viewMatrix[2][0]);
    vec3 down = vec3(viewMatrix[0][1], viewMatrix[1][1], viewMatrix[2][1]);
    vec3 forward = vec3(viewMatrix[0][2], viewMatrix[1][2], viewMatrix[2][2]);
    float z = dot(d, forward), dn = dot(d, n);
    if (z <= 0.0 || abs(dn) < 1e-4 * length(d)) return;
    // One pixel moves the ray's point at depth z by z / f along the axis (f in pixels:
    // projMatrix[0][0] = 2 fx / width, docs/realtime-renderer.md "Camera and lens").
    vec3 ex = right * (2.0 * z / (abs(projMatrix[0][0]) * canvas.x));
    vec3 ey = down * (2.0 * z / (abs(projMatrix[1][1]) * canvas.y));
    shadowPixelDx = ex - d * (dot(ex, n) / dn);
    shadowPixelDy = ey - d * (dot(ey, n) / dn);
}

// Texture coordinate of p in light li's focused map k; inside: p lies in its frustum.
vec2 focusMapCoord(int li, int k, vec3 p, out bool inside) {
    vec4 c = lights[li].focusViewProj[k] * vec4(p, 1.0);
    vec2 ndc = c.xy / c.w;
    inside = c.w > 0.0 && all(lessThanEqual(abs(ndc), vec2(1.0)));
    return ndc * 0.5 + 0.5;
}

// The virtual occluders' focused maps of light li (GpuLight::focusMaps): all-occluder atlas
// layers firstFocusLayer.., each looked up through its focusViewProj, whose texels are finer by
// the light's frustum over the focused one (at least 2x). Filtered over the camera pixel's
// footprint in the map (shadowPixelDx / Dy projected; a box of that width per axis convolved
// with the bilinear hat, at most 2 texels): the reference's hard edge is antialiased by the
// pixel's box filter, which the bilinear lookup's 1-texel ramp misses where a texel is finer
// than the pixel and the 2-texel PCF overshoots where it is not much finer. Without a
// footprint, the 2-texel PCF. Outside a map's frustum none of its occluders lies between p and
// the light. d is p's light distance (lightDistance). docs/realtime-renderer.md, "Focused maps
// for the virtual occluders".
float focusedVirtualVisibility(sampler2DArray allMap, int li, vec3 p, float NdotL, float d) {
    float mapSize = float(textureSize(allMap, 0).x);
    float cosL = max(NdotL, 0.2);
    float slope = sqrt(1.0 - cosL * cosL) / cosL;  // as shadowFootprint's for PCF
    bool footprint = dot(shadowPixelDx, shadowPixelDx) + dot(shadowPixelDy, shadowPixelDy) > 0.0;
    float vis = 1.0;
    for (int k = 0; k < kMaxFocusMaps; ++k) {
        if (k >= lights[li].focusMaps) break;
        bool inside, unused;
        vec2 t = focusMapCoord(li, k, p, inside);
        if (!inside) continue;
        vec2 w = vec2(2.0);
        if (footprint) {  // texels per pixel: the footprint's spread along each map axis
            vec2 tx = (focusMapCoord(li, k, p + shadowPixelDx, unused) - t) * mapSize;
            vec2 ty = (focusMapCoord(li, k, p + shadowPixelDy, unused) - t) * mapSize;
            w = clamp(sqrt(tx * tx + ty * ty), vec2(0.05), vec2(2.0));
        }
        float size = lights[li].focusFrustumSize[k];
        float extent = lights[li].type == LIGHT_DIRECTIONAL ? 2.0 * size : 2.0 * size * d;
        float ref = d - (shadowBias + 1.5 * extent / mapSize * slope);
        vec2 fr = fract(t * mapSize - 0.5);
        vis *= shadowPcfWeighted(allMap, vec3(t, float(lights[li].firstFocusLayer + k)), ref,
                                 boxHatWeights(fr.x, w.x), boxHatWeights(fr.y, w.y));
    }
    return vis;
}

// Visibility through every occluder (x) and the real ones (y) where the light's virtual
// occluders have their focused map: the real map's times the virtual one's (for a point light's
// hard shadow, visible = no real and no virtual occluder in the way).
vec2 shadowVisibilityFocused(sampler2DArray allMap, sampler2DArray realMap, int li, vec3 p,
                             float NdotL, int layer, vec2 t, float d, float bias, vec2 fr) {
    float visReal = shadowVisibilityAt(realMap, realMap, layer, t, d, bias, fr, false).x;
    float visVirtual = focusedVirtualVisibility(allMap, li, p, NdotL, d);
    if (lights[li].unfocusedVirtual == 1)  // in the light's own layer of the all-occluder atlas
        visVirtual *= shadowVisibilityAt(allMap, allMap, layer, t, d, bias, fr, false).x;
    return vec2(visReal * visVirtual, visReal);
}

vec2 shadowVisibility(sampler2DArray allMap, sampler2DArray realMap, int li, vec3 p, float NdotL,
                      bool withReal) {
    int layer;
    vec2 t, fr;
    float d, bias;
    if (!shadowFootprint(li, p, NdotL, float(textureSize(allMap, 0).x), layer, t, d, bias, fr))
        return vec2(1.0);
    if (lights[li].focusMaps > 0)
        return shadowVisibilityFocused(allMap, realMap, li, p, NdotL, layer, t, d, bias, fr);
    return shadowVisibilityAt(allMap, realMap, layer, t, d, bias, fr, withReal);
}

#ifdef MIRAGE_GLASS_SHADOWS
// Coloured transmittance of the glass between the light and p (shadow_glass.frag) at the shadow
// footprint (the glass atlases have the shadow atlases' size and layers): the layer's summed
// ln(transmittance), applied in the fraction of the 2x2 footprint where the nearest glass is
// closer to the light than p. Multiplies tAll (all glass) and, when `withReal`, tReal (real glass
// only; else tReal = tAll's factor too). Every glass surface along the light's ray counts once p
// is behind the nearest: a receiver between two glass objects on one ray is tinted by both.
void glassTransmittanceAt(sampler2DArray glassAll, sampler2DArray glassReal, int layer, vec2 t,
                          float d, float bias, vec2 fr, bool withReal, inout vec3 tAll,
                          inout vec3 tReal) {
    vec3 tc = vec3(t, float(layer));
    float behind = bilinearGather(step(textureGather(glassAll, tc, 3), vec4(d - bias)), fr);
    vec3 ga = mix(vec3(1.0), exp(min(texture(glassAll, tc).rgb, vec3(0.0))), behind);
    tAll *= ga;
    if (!withReal) {
        tReal *= ga;
        return;
    }
    float behindR = bilinearGather(step(textureGather(glassReal, tc, 3), vec4(d - bias)), fr);
    tReal *= mix(vec3(1.0), exp(min(texture(glassReal, tc).rgb, vec3(0.0))), behindR);
}
#endif

// Light li's visibility at p through every occluder (visAll) and through real occluders only
// (visReal), coloured by the glass between when glass transmits this light. The layer search
// runs once for the opaque and the glass atlases, and the glass atlases are read only for lights
// whose cone holds glass (lights[li].glassShadow): a light without glass costs what it cost
// before glass shadows existed.
#ifdef MIRAGE_GLASS_SHADOWS
#define MIRAGE_GLASS_ARGS , sampler2DArray glassAll, sampler2DArray glassReal
#else
#define MIRAGE_GLASS_ARGS
#endif
void lightVisibility(sampler2DArray allMap, sampler2DArray realMap MIRAGE_GLASS_ARGS, int li,
                     vec3 p, float NdotL, out vec3 visAll, out vec3 visReal) {
    visAll = vec3(1.0);
    visReal = vec3(1.0);
    int layer;
    vec2 t, fr;
    float d, bias;
    if (!shadowFootprint(li, p, NdotL, float(textureSize(allMap, 0).x), layer, t, d, bias, fr))
        return;
    bool withReal = lights[li].realOnlyMap == 1;
    vec2 vis = lights[li].focusMaps > 0
                   ? shadowVisibilityFocused(allMap, realMap, li, p, NdotL, layer, t, d, bias, fr)
                   : shadowVisibilityAt(allMap, realMap, layer, t, d, bias, fr, withReal);
    visAll = vec3(vis.x);
    visReal = vec3(vis.y);
#ifdef MIRAGE_GLASS_SHADOWS
    if (lights[li].glassShadow == 1)
        glassTransmittanceAt(glassAll, glassReal, layer, t, d, bias, fr, withReal, visAll,
                             visReal);
#endif
}

// The GGX specular lobe alone (Smith-Schlick G, Schlick F from F0) times cos: the glossy
// highlight of a punctual light, also on rough mirrors, metals and glass (direct.frag).
vec3 ggxSpecularCos(vec3 n, vec3 v, vec3 l, vec3 F0, float roughness, out vec3 F) {
    float NdotL = max(dot(n, l), 0.0);
    float NdotV = max(dot(n, v), 1e-4);
    F = F0;
    if (NdotL <= 0.0) return vec3(0.0);
    vec3 h = normalize(l + v);
    float NdotH = max(dot(n, h), 0.0), VdotH = max(dot(v, h), 0.0);
    float a = max(roughness * roughness, 1e-3), a2 = a * a;
    float dd = NdotH * NdotH * (a2 - 1.0) + 1.0;
    float D = a2 / (PI * dd * dd);
    float k = a * 0.5;
    float G = (NdotL / (NdotL * (1.0 - k) + k)) * (NdotV / (NdotV * (1.0 - k) + k));
    F = F0 + (1.0 - F0) * pow(1.0 - VdotH, 5.0);
    return D * G * F / (4.0 * NdotL * NdotV) * NdotL;
}

// Lambert diffuse + GGX specular (Smith-Schlick G, Schlick F, F0 = 0.04 for dielectrics), glTF
// metallic-roughness. Returns BRDF * cos (the factor multiplying incident irradiance).
vec3 brdfCos(vec3 n, vec3 v, vec3 l, vec3 baseColor, float metallic, float roughness) {
    float NdotL = max(dot(n, l), 0.0);
    if (NdotL <= 0.0) return vec3(0.0);
    vec3 F;
    vec3 spec = ggxSpecularCos(n, v, l, mix(vec3(0.04), baseColor, metallic), roughness, F);
    vec3 diffuse = (1.0 - F) * (1.0 - metallic) * baseColor / PI;
    return spec + diffuse * NdotL;
}

#endif
