#version 450 core
#include "common.glsl"
#include "passes/specular/specular.glsl"
#include "passes/fuzzy/fuzzy.glsl"
// The video term of Eqs. 9-10 per rough pixel, before filtering: what the composite takes for
// the reflected and the refracted hit, CI_bp = sum over the two of eta CI_r(hit) when the hit is
// real and back-projects into the video (depth-validated), its rendered real share of L'_r when it
// is real but cannot be back-projected, 0 when it is virtual or a miss (their light is in dL' /
// L_env). Camera units (linear, exposure applied). a = 1 marks a rough pixel, 0 elsewhere.
in vec2 uv;
layout(binding = kUnitFuzzyEmissive) uniform sampler2D gEmissive;      // a = specular slot + 1
layout(binding = kUnitFuzzyReflHit) uniform sampler2D reflHit;         // xyz hit, w = origin
layout(binding = kUnitFuzzyReflWeight) uniform sampler2D reflWeight;   // eta1 (rgb)
layout(binding = kUnitFuzzyCamera) uniform sampler2D cameraImage;      // sRGB8: samples linear
layout(binding = kUnitFuzzyRealSurfaces) uniform sampler2D realSurfaces;
layout(binding = kUnitFuzzyCanvasToCamera) uniform sampler2D canvasToCamera;
layout(binding = kUnitFuzzySpecRRefl) uniform sampler2D specRRefl;     // reflection share of L'_r
layout(binding = kUnitFuzzySpecR) uniform sampler2D specR;             // L'_r
layout(binding = kUnitFuzzyRefrHit) uniform sampler2D refrHit;         // GBuf_refr: xyz, w = origin
layout(binding = kUnitFuzzyRefrWeight) uniform sampler2D refrWeight;   // eta2 T (rgb)
uniform float depthEpsilon;  // RendererOptions::backProjectionEpsilon
layout(location = 0) out vec4 outVideo;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    outVideo = vec4(0.0);
    if (roughSlot(texelFetch(gEmissive, px, 0).a) < 0) return;
    vec3 ex = exposure;
    vec3 r = max(texelFetch(specR, px, 0).rgb, vec3(0.0)) * ex;
    vec3 rRefl = clamp(texelFetch(specRRefl, px, 0).rgb * ex, vec3(0.0), r);
    vec3 c = vec3(0.0);
    for (int k = 0; k < 2; ++k) {  // as composite.frag's compositeSpecular
        vec4 P = k == 0 ? texelFetch(reflHit, px, 0) : texelFetch(refrHit, px, 0);
        vec3 w = (k == 0 ? texelFetch(reflWeight, px, 0) : texelFetch(refrWeight, px, 0)).rgb;
        if (all(lessThanEqual(w, vec3(0.0))) || int(P.w + 0.5) != ORIGIN_REAL) continue;
        vec3 video;
        if (backProject(P.xyz, realSurfaces, canvasToCamera, cameraImage, depthEpsilon, video))
            c += w * video;
        else
            c += k == 0 ? rRefl : max(r - rRefl, vec3(0.0));  // rendered real share
    }
    outVideo = vec4(allFinite(c) ? c : vec3(0.0), 1.0);
}
