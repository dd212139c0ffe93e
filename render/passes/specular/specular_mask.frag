#version 450 core
#include "common.glsl"
// Depth mask of the specular pixels for the passes that shade only them: depth 0 where the
// primary G-buffer shows a mirror or glass object (gEmissive.a = specular slot + 1), 1 elsewhere.
// Those passes draw their full-screen triangle at depth 0.5 with GL_GREATER: llvmpipe's early
// depth test then skips every SIMD block without a specular pixel before the shader runs, where a
// `return` in the shader would only mask lanes and still run the whole trace.
layout(binding = kUnitSpecGbufEmissive) uniform sampler2D gEmissive;
void main() {
    gl_FragDepth = texelFetch(gEmissive, ivec2(gl_FragCoord.xy), 0).a > 0.5 ? 0.0 : 1.0;
}
