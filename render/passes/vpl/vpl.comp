#version 450 core
#include "common.glsl"
// Places VPLs by sampling the reflective shadow maps (Keller's instant radiosity with Dachsbacher
// & Stamminger's RSMs): one invocation per VPL. Each light owns a contiguous VPL range; a light's
// samples form a Hammersley set over its layers' image squares (the same every frame, so a static
// scene has no VPL flicker, unless VplOptions::temporalRotation shifts it every frame). A VPL's flux is the RSM's reflected intensity times the solid angle
// its sample stands for.
//
// Reflected and refracted VPLs (Knecht 2013 Sec. 5.2): a sample on a mirror or glass of a spot
// light with photon G-buffers continues to the receiver of that point's reflected or refracted
// photon. When both exist a Halton (base 3) choice takes one and doubles its power (the same
// choice every frame, unless VplOptions::temporalRotation moves it along the sequence). Its flux is
// the photon's power (W, visibility included) scaled from the photon texel's solid angle to the
// sample's, times the receiver's diffuse albedo: so caustics emit coloured indirect light.
layout(local_size_x = 64) in;
layout(std430, binding = kBindingVpls) writeonly buffer Vpls { GpuVpl vpls[]; };
layout(binding = kUnitVplRsmFlux) uniform sampler2DArray rsmFlux;      // rgb W/sr * albedo, a = real
layout(binding = kUnitVplRsmNormal) uniform sampler2DArray rsmNormal;
layout(binding = kUnitVplRsmPosition) uniform sampler2DArray rsmPosition;  // xyz world, w = 1 where covered
uniform ivec4 lightVplFirst[MAX_LIGHTS];  // x = first VPL, y = count, z = 1 if the light has an RSM,
                                          // w = its photon G-buffer layer (-1: none)
layout(binding = kUnitVplPhotonHitRefl) uniform sampler2DArray photonHitRefl;  // Resource::Photon*
layout(binding = kUnitVplPhotonPowerRefl) uniform sampler2DArray photonPowerRefl;
layout(binding = kUnitVplPhotonSurfaceRefl) uniform usampler2DArray photonSurfaceRefl;
layout(binding = kUnitVplPhotonHitRefr) uniform sampler2DArray photonHitRefr;
layout(binding = kUnitVplPhotonPowerRefr) uniform sampler2DArray photonPowerRefr;
layout(binding = kUnitVplPhotonSurfaceRefr) uniform usampler2DArray photonSurfaceRefr;
uniform mat4 causticViewProj[MAX_LIGHTS];  // world -> clip of each light's photon frustum
uniform float causticTanHalf[MAX_LIGHTS];  // tan of that frustum's half angle
uniform int photonMapSize;                 // photon G-buffer texels per side
// Added to every sample's image-square position, modulo 1 (VplOptions::temporalRotation; 0: the
// same set every frame).
uniform vec2 sampleOffset;
uniform int haltonFrame;  // the frame index with VplOptions::temporalRotation, else 0

float radicalInverse2(uint bits) {
    bits = (bits << 16u) | (bits >> 16u);
    bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
    bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
    bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
    bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
    return float(bits) * 2.3283064365386963e-10;
}

float radicalInverse3(uint i) {
    float f = 1.0, r = 0.0;
    while (i > 0u) {
        f /= 3.0;
        r += f * float(i % 3u);
        i /= 3u;
    }
    return r;
}

// The VPL that continues from point p on a mirror or glass (the RSM sample standing for
// `sampleSolidAngle` sr of light li) to the receiver of p's photon in layer `layer`. Left invalid
// when p lies outside the photon frustum or neither photon reaches a modelled surface.
void followSpecular(int li, int layer, vec3 p, float sampleSolidAngle, uint k, inout GpuVpl v) {
    v.valid = 0;
    vec4 c = causticViewProj[li] * vec4(p, 1.0);
    if (c.w <= 0.0) return;
    vec2 ndc = c.xy / c.w;
    if (any(greaterThan(abs(ndc), vec2(1.0)))) return;
    float size = float(photonMapSize);
    ivec2 texel = clamp(ivec2((ndc * 0.5 + 0.5) * size), ivec2(0), ivec2(photonMapSize - 1));
    ivec3 tc = ivec3(texel, layer);
    vec4 hitL = texelFetch(photonHitRefl, tc, 0), powL = texelFetch(photonPowerRefl, tc, 0);
    vec4 hitT = texelFetch(photonHitRefr, tc, 0), powT = texelFetch(photonPowerRefr, tc, 0);
    bool hasL = hitL.w >= 1.0 && dot(powL.rgb, vec3(1.0)) * powL.a > 0.0;
    bool hasT = hitT.w >= 1.0 && dot(powT.rgb, vec3(1.0)) * powT.a > 0.0;
    if (!hasL && !hasT) return;
    // With the per-frame rotation the choice moves along the Halton sequence frame by frame, so
    // each sample takes either photon about every second frame (Knecht 2013 Sec. 5.2).
    bool takeL = hasL && (!hasT || radicalInverse3(k + 1u + uint(haltonFrame)) < 0.5);
    float pick = hasL && hasT ? 2.0 : 1.0;  // the other photon's share, carried by this one
    vec4 hit = takeL ? hitL : hitT;
    vec4 pw = takeL ? powL : powT;
    uvec4 s = takeL ? texelFetch(photonSurfaceRefl, tc, 0) : texelFetch(photonSurfaceRefr, tc, 0);
    vec2 s0 = unpackHalf2x16(s.x), s1 = unpackHalf2x16(s.y), s2 = unpackHalf2x16(s.z);
    vec3 n = vec3(s0, s1.x);
    vec3 albedo = vec3(s1.y, s2);
    // The photon texel's solid angle (pixel counting, as photon_gbuffer.frag).
    float t = causticTanHalf[li];
    vec2 texelNdc = (vec2(texel) + 0.5) / size * 2.0 - 1.0;
    float texelTan = 2.0 * t / size;
    float photonSolidAngle = texelTan * texelTan / pow(1.0 + t * t * dot(texelNdc, texelNdc), 1.5);
    int origin = int(floor(hit.w / 4.0));
    float realVis = hit.w - 4.0 * float(origin);
    realVis = realVis > 1.5 ? realVis - 2.0 : realVis;  // + 2: scattered over a rough lobe
    v.position = hit.xyz;
    v.normal = normalize(n);
    v.isReal = origin == ORIGIN_REAL && realVis > 0.5 ? 1 : 0;
    v.flux = albedo * pw.rgb * pw.a * (sampleSolidAngle / max(photonSolidAngle, 1e-12)) * pick;
    v.tangent = normalize(abs(v.normal.y) < 0.99 ? cross(v.normal, vec3(0, 1, 0))
                                                 : cross(v.normal, vec3(1, 0, 0)));
    v.valid = allFinite(v.flux) && allFinite(v.normal) && allFinite(v.position) ? 1 : 0;
}

void main() {
    int id = int(gl_GlobalInvocationID.x);
    if (id >= vplCount) return;
    GpuVpl v;
    v.position = vec3(0.0);
    v.isReal = 0;
    v.normal = vec3(0.0, 1.0, 0.0);
    v.valid = 0;  // unused slot
    v.flux = vec3(0.0);
    v.pad0 = 0.0;
    v.tangent = vec3(1.0, 0.0, 0.0);
    v.pad1 = 0.0;
    for (int li = 0; li < lightCount; ++li) {
        ivec4 r = lightVplFirst[li];
        if (r.z == 0 || id < r.x || id >= r.x + r.y) continue;
        int type = lights[li].type;
        int local = id - r.x;
        int layers = max(lights[li].shadowLayers, 1);
        int layer = local % layers;
        int perLayer = max(r.y / layers, 1);
        int k = local / layers;
        if (k >= perLayer) break;  // remainder of a count not divisible by the layers
        vec2 uv = fract(vec2((float(k) + 0.5) / float(perLayer), radicalInverse2(uint(k))) +
                        sampleOffset);
        vec3 tc = vec3(uv, float(lights[li].firstShadowLayer + layer));
        vec4 pos = textureLod(rsmPosition, tc, 0.0);
        if (pos.w < 0.5) break;  // the sample sees no geometry
        vec4 flux = textureLod(rsmFlux, tc, 0.0);
        vec2 ndc = uv * 2.0 - 1.0;
        float t = lights[li].frustumSize;  // tan(half fov), or ortho half extent (m) for dir.
        float cell = (2.0 * t) * (2.0 * t) / float(perLayer);
        float weight = type == LIGHT_DIRECTIONAL
                           ? cell
                           : cell / pow(1.0 + t * t * dot(ndc, ndc), 1.5);
        vec4 normal = textureLod(rsmNormal, tc, 0.0);
        if (normal.w > 0.5 && r.w >= 0) {  // on a mirror or glass: follow the photon
            followSpecular(li, r.w, pos.xyz, weight, uint(k), v);
            break;
        }
        v.position = pos.xyz;
        v.isReal = (lights[li].isReal == 1 && flux.a > 0.5) ? 1 : 0;
        v.normal = normalize(normal.xyz);
        v.valid = 1;
        v.flux = flux.rgb * weight;
        vec3 n = v.normal;
        v.tangent = normalize(abs(n.y) < 0.99 ? cross(n, vec3(0, 1, 0)) : cross(n, vec3(1, 0, 0)));
        if (!allFinite(v.flux) || !allFinite(v.normal)) v.valid = 0;
        break;
    }
    vpls[id] = v;
}
