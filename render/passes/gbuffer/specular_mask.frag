#version 450 core
#include "common.glsl"
// Depth mask of the specular pixels: depth 0 where the G-buffer shows a mirror or glass object
// (gEmissive.a = specular slot + 1), 1 elsewhere. The passes that shade only those pixels draw
// their full-screen triangle at depth 0.5 with GL_GREATER, the passes whose light there would go
// unused (the composite takes a specular pixel's light from the specular passes) with GL_LESS:
// llvmpipe's early depth test then skips every SIMD block the test rejects before the shader
// runs, where a `return` in the shader would only mask lanes and still run all of it.
layout(binding = kUnitMaskEmissive) uniform sampler2D gEmissive;
void main() {
    gl_FragDepth = texelFetch(gEmissive, ivec2(gl_FragCoord.xy), 0).a > 0.5 ? 0.0 : 1.0;
}
