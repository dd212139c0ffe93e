#version 450 core
#include "common.glsl"
// Places VPLs by sampling the reflective shadow maps (Keller's instant radiosity with Dachsbacher
// & Stamminger's RSMs): one invocation per VPL. Each light owns a contiguous VPL range; a light's
// samples form a Hammersley set over its layers' image squares (the same every frame, so a static
// scene has no VPL flicker). A VPL's flux is the RSM's reflected intensity times the solid angle
// its sample stands for.
layout(local_size_x = 64) in;
layout(std430, binding = kBindingVpls) writeonly buffer Vpls { GpuVpl vpls[]; };
layout(binding = kUnitVplRsmFlux) uniform sampler2DArray rsmFlux;      // rgb W/sr * albedo, a = real
layout(binding = kUnitVplRsmNormal) uniform sampler2DArray rsmNormal;
layout(binding = kUnitVplRsmPosition) uniform sampler2DArray rsmPosition;  // xyz world, w = 1 where covered
uniform ivec4 lightVplFirst[MAX_LIGHTS];  // x = first VPL, y = count, z = 1 if the light has an RSM

float radicalInverse2(uint bits) {
    bits = (bits << 16u) | (bits >> 16u);
    bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
    bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
    bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
    bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
    return float(bits) * 2.3283064365386963e-10;
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
        vec2 uv = vec2((float(k) + 0.5) / float(perLayer), radicalInverse2(uint(k)));
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
        v.position = pos.xyz;
        v.isReal = (lights[li].isReal == 1 && flux.a > 0.5) ? 1 : 0;
        v.normal = normalize(textureLod(rsmNormal, tc, 0.0).xyz);
        v.valid = 1;
        v.flux = flux.rgb * weight;
        vec3 n = v.normal;
        v.tangent = normalize(abs(n.y) < 0.99 ? cross(n, vec3(0, 1, 0)) : cross(n, vec3(1, 0, 0)));
        if (!allFinite(v.flux) || !allFinite(v.normal)) v.valid = 0;
        break;
    }
    vpls[id] = v;
}
