#version 450 core
#include "common.glsl"
#include "temporal.glsl"
// Which canvas pixels the caustic resolve must shade (depth 0) and which hold no caustic light
// (depth 1; the resolve's early depth test skips them and they keep the cleared 0): a receiver
// (a surface, not a mirror or glass) in an 8x8 tile that a photon's kernel reached this frame,
// or whose position was, in last frame's canvas, on a tile where the caustic's history is not 0
// (the four tiles its bilinear history lookup can touch). On llvmpipe a fragment shader costs
// every instruction of every branch, so skipping the caustic-free pixels must happen before
// the shader runs: by the depth test.
in vec2 uv;
layout(binding = kUnitClassifyPosition) uniform sampler2D gPosition;  // w = origin
layout(binding = kUnitClassifyEmissive) uniform sampler2D gEmissive;  // a = specular slot + 1
layout(binding = kUnitClassifyPhotonTiles) uniform usampler2D photonTiles;
layout(binding = kUnitClassifyHistoryTiles) uniform usampler2D historyTiles;
uniform int usePhotons;  // 1: photons were splatted this frame
uniform int useHistory;  // 1: the resolve blends last frame's caustic in
uniform int everywhere;  // 1: every pixel (CausticOptions::resolveEverywhere, tests)

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 P = texelFetch(gPosition, px, 0);
    bool receiver = int(P.w + 0.5) != ORIGIN_NONE && texelFetch(gEmissive, px, 0).a <= 0.5;
    bool photons = usePhotons != 0 && texelFetch(photonTiles, px >> 3, 0).r != 0u;
    bool history = false;
    vec2 puv;
    if (useHistory != 0 && reprojectToPreviousFrame(P.xyz, puv)) {
        ivec2 last = ivec2(canvas.xy) - 1;
        ivec2 t0 = clamp(ivec2(floor(puv * canvas.xy - 0.5)), ivec2(0), last) >> 3;
        ivec2 t1 = clamp(ivec2(floor(puv * canvas.xy - 0.5)) + 1, ivec2(0), last) >> 3;
        history = texelFetch(historyTiles, t0, 0).r != 0u ||
                  texelFetch(historyTiles, ivec2(t1.x, t0.y), 0).r != 0u ||
                  texelFetch(historyTiles, ivec2(t0.x, t1.y), 0).r != 0u ||
                  texelFetch(historyTiles, t1, 0).r != 0u;
    }
    gl_FragDepth = everywhere != 0 || (receiver && (photons || history)) ? 0.0 : 1.0;
}
