#version 450 core
#include "common.glsl"
#include "passes/specular/specular.glsl"
// Level 0 of the rough-refraction pass's mip chains (canvas size; glGenerateMipmap builds the
// rest, a box filter, so every level holds averages of what is below: LEAN mapping's linear
// filtering of moments, Olano and Baker 2010):
//   0-2: the back faces' normal moments, LEAN-mapped: c n, c (nx^2, ny^2, nz^2),
//        c (nx ny, nx nz, ny nz), a = c, with c = 1 on a back face of a rough-glass object
//        (world frame, outward unit normal) and 0 elsewhere, so that any level divided by its a
//        is the first and second moment of the normals it covers;
//   3-7: L'_rv, L'_r, the reflection's share of L'_r, L_env and the video term CI_bp resolved
//        as the composite resolves a sharp pixel (fuzzy_resolve.frag: eta CI_r(hit) per real
//        hit that back-projects, its rendered real share otherwise, 0 for virtual hits and
//        misses; camera units), each times g, a = g, with g = 1 on a rough-glass pixel: what
//        the lobes see, prefiltered (never mixed with other pixels).
in vec2 uv;
layout(std430, binding = kBindingSpecularDraws) readonly buffer SpecularDraws { GpuSpecularDraw specularDraws[]; };
layout(binding = kUnitRoughBackPosition) uniform sampler2D backPosition;  // w = slot + 1
layout(binding = kUnitRoughBackNormal) uniform sampler2D backNormal;      // outward unit normal
layout(binding = kUnitRoughEmissive) uniform sampler2D gEmissive;         // a = slot + 1
layout(binding = kUnitRoughSpecFirst + 0) uniform sampler2D specRv;
layout(binding = kUnitRoughSpecFirst + 1) uniform sampler2D specR;
layout(binding = kUnitRoughSpecFirst + 2) uniform sampler2D specRRefl;
layout(binding = kUnitRoughSpecFirst + 3) uniform sampler2D lEnv;
layout(binding = kUnitRoughReflHit) uniform sampler2D reflHit;        // xyz hit / dir, w = origin
layout(binding = kUnitRoughReflWeight) uniform sampler2D reflWeight;  // eta1
layout(binding = kUnitRoughRefrHit) uniform sampler2D refrHit;
layout(binding = kUnitRoughRefrWeight) uniform sampler2D refrWeight;  // eta2 T
layout(binding = kUnitRoughRealSurfaces) uniform sampler2D realSurfaces;
layout(binding = kUnitRoughCanvasToCamera) uniform sampler2D canvasToCamera;
layout(binding = kUnitRoughCamera) uniform sampler2D cameraImage;     // sRGB8: samples linear
uniform float depthEpsilon;  // RendererOptions::backProjectionEpsilon
layout(location = 0) out vec4 outMean;
layout(location = 1) out vec4 outSquares;
layout(location = 2) out vec4 outProducts;
layout(location = 3) out vec4 outRv;
layout(location = 4) out vec4 outR;
layout(location = 5) out vec4 outRRefl;
layout(location = 6) out vec4 outEnv;
layout(location = 7) out vec4 outVideo;

bool roughGlass(float slotPlusOne) {
    int slot = int(slotPlusOne + 0.5) - 1;
    return slot >= 0 && specularDraws[slot].rough == kRoughGlass;
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 n = texelFetch(backNormal, px, 0).xyz;
    float c = roughGlass(texelFetch(backPosition, px, 0).w) && dot(n, n) > 0.25 ? 1.0 : 0.0;
    n = c > 0.0 ? normalize(n) : vec3(0.0);
    outMean = vec4(c * n, c);
    outSquares = vec4(c * n * n, c);
    outProducts = vec4(c * vec3(n.x * n.y, n.x * n.z, n.y * n.z), c);
    outRv = outR = outRRefl = outEnv = outVideo = vec4(0.0);
    if (!roughGlass(texelFetch(gEmissive, px, 0).a)) return;
    outRv = vec4(texelFetch(specRv, px, 0).rgb, 1.0);
    outR = vec4(texelFetch(specR, px, 0).rgb, 1.0);
    outRRefl = vec4(texelFetch(specRRefl, px, 0).rgb, 1.0);
    outEnv = vec4(texelFetch(lEnv, px, 0).rgb, 1.0);
    vec3 ex = exposure;  // as fuzzy_resolve.frag / composite.frag's compositeSpecular
    vec3 r = max(outR.rgb, vec3(0.0)) * ex;
    vec3 rRefl = clamp(outRRefl.rgb * ex, vec3(0.0), r);
    vec3 ciBp = vec3(0.0);
    for (int k = 0; k < 2; ++k) {
        vec4 P = k == 0 ? texelFetch(reflHit, px, 0) : texelFetch(refrHit, px, 0);
        vec3 w = (k == 0 ? texelFetch(reflWeight, px, 0) : texelFetch(refrWeight, px, 0)).rgb;
        if (all(lessThanEqual(w, vec3(0.0))) || int(P.w + 0.5) != ORIGIN_REAL) continue;
        vec3 video;
        if (backProject(P.xyz, realSurfaces, canvasToCamera, cameraImage, depthEpsilon, video))
            ciBp += w * video;
        else
            ciBp += k == 0 ? rRefl : max(r - rRefl, vec3(0.0));  // rendered real share
    }
    outVideo = vec4(allFinite(ciBp) ? ciBp : vec3(0.0), 1.0);
}
