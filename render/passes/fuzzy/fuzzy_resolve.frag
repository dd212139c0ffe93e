#version 450 core
#include "common.glsl"
#include "passes/specular/specular.glsl"
#include "passes/fuzzy/fuzzy.glsl"
// The reflection's video term per rough-metal pixel, before filtering: what the composite's
// Eqs. 9-10 take for the reflected hit p_refl, i.e. eta1 CI_r(p_refl) when the hit is real and
// back-projects into the video (depth-validated), its rendered real share of L'_r when it is real
// but cannot be back-projected, 0 when it is virtual or a miss (their light is in dL' / L_env).
// Camera units (linear, exposure applied). a = 1 marks a rough-metal pixel, 0 elsewhere.
in vec2 uv;
layout(binding = kUnitFuzzyEmissive) uniform sampler2D gEmissive;      // a = specular slot + 1
layout(binding = kUnitFuzzyReflHit) uniform sampler2D reflHit;         // xyz hit, w = origin
layout(binding = kUnitFuzzyReflWeight) uniform sampler2D reflWeight;   // eta1 (rgb)
layout(binding = kUnitFuzzyCamera) uniform sampler2D cameraImage;      // sRGB8: samples linear
layout(binding = kUnitFuzzyRealSurfaces) uniform sampler2D realSurfaces;
layout(binding = kUnitFuzzyCanvasToCamera) uniform sampler2D canvasToCamera;
layout(binding = kUnitFuzzySpecRRefl) uniform sampler2D specRRefl;     // reflection share of L'_r
uniform float depthEpsilon;  // RendererOptions::backProjectionEpsilon
layout(location = 0) out vec4 outVideo;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    outVideo = vec4(0.0);
    if (roughSlot(texelFetch(gEmissive, px, 0).a) < 0) return;
    vec4 P = texelFetch(reflHit, px, 0);
    vec3 w = max(texelFetch(reflWeight, px, 0).rgb, vec3(0.0));
    vec3 c = vec3(0.0);
    if (int(P.w + 0.5) == ORIGIN_REAL) {
        vec3 video;
        c = backProject(P.xyz, realSurfaces, canvasToCamera, cameraImage, depthEpsilon, video)
                ? w * video
                : max(texelFetch(specRRefl, px, 0).rgb, vec3(0.0)) * exposure;
    }
    outVideo = vec4(allFinite(c) ? c : vec3(0.0), 1.0);
}
