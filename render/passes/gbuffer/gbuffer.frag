#version 450 core
#include "common.glsl"
// Deferred G-buffer, all linear: world position + origin, world normal + roughness,
// base colour + metallic, emitted radiance. The material comes flat from gbuffer.vert.
uniform int origin;  // ORIGIN_REAL or ORIGIN_VIRTUAL
uniform int specularSlot;  // index into GpuScene::specularDraws(), -1 = not specular
in vec3 worldPos;
in vec3 worldNormal;
in vec2 uv;
flat in vec4 materialBaseMetallic;
flat in vec4 materialEmissiveRough;
flat in float materialTranslucentIor;  // > 0: a participating medium, its boundary's IOR
#ifdef MIRAGE_BASE_COLOR_MAPS
layout(binding = kUnitBaseColorMap) uniform sampler2D baseColorMap;  // sRGB texture: samples are linear
#endif
#ifdef MIRAGE_METALLIC_ROUGHNESS_MAPS
layout(binding = kUnitMetallicRoughnessMap) uniform sampler2D metallicRoughnessMap;  // linear
#endif
layout(location = 0) out vec4 gPosition;  // xyz world (m), w = origin
layout(location = 1) out vec4 gNormal;    // xyz unit world normal (facing the camera), w = roughness
layout(location = 2) out vec4 gAlbedo;    // rgb linear base colour, a = metallic
layout(location = 3) out vec4 gEmissive;  // rgb linear emitted radiance, a = specular slot + 1
                                          // (0: not a mirror / glass pixel); a translucent
                                          // object: a = -IOR of its boundary (<= -1)
layout(location = 4) out vec4 gRealSurface;  // = gPosition; GBufferPass masks it off for the
                                             // virtual draws (RealSurfaces)
void main() {
    vec3 n = normalize(worldNormal);
    if (!allFinite(n)) n = vec3(0.0, 1.0, 0.0);
    // Shade the side the camera sees (proxies are often single quads seen from either side).
    if (dot(n, cameraPos.xyz - worldPos) < 0.0) n = -n;
    gPosition = vec4(worldPos, float(origin));
    gRealSurface = gPosition;
    // glTF: the factors times the texture's G (roughness) and B (metallic), per pixel, so a
    // rough-glass object can be frosted in parts (render/passes/rough reads gNormal.w). Scenes
    // without such textures compile without the reads (a white texture costs as much to read).
#ifdef MIRAGE_METALLIC_ROUGHNESS_MAPS
    vec4 mr = texture(metallicRoughnessMap, uv);
#else
    const vec4 mr = vec4(1.0);
#endif
#ifdef MIRAGE_BASE_COLOR_MAPS
    vec3 baseColor = materialBaseMetallic.rgb * texture(baseColorMap, uv).rgb;
#else
    vec3 baseColor = materialBaseMetallic.rgb;
#endif
    gNormal = vec4(n, clamp(materialEmissiveRough.a * mr.g, 0.02, 1.0));
    gAlbedo = vec4(baseColor, clamp(materialBaseMetallic.a * mr.b, 0.0, 1.0));
    gEmissive = vec4(materialEmissiveRough.rgb,
                     materialTranslucentIor > 0.0 ? -materialTranslucentIor
                                                  : float(specularSlot + 1));
}
