#version 450 core
#include "common.glsl"
// Depth mask of the camera pixels the full composite variant must shade: depth 0 where the canvas
// pixel a camera pixel sees (the lens remap) shows a mirror or glass object (gEmissive.a =
// specular slot + 1), 1 elsewhere. The diffuse variant is then drawn at depth 0.5 with GL_LESS
// and the full variant with GL_GREATER: llvmpipe's early depth test skips every SIMD block whose
// pixels all fail before the shader runs, so each pixel runs one variant.
layout(binding = kUnitCompositeRemap) uniform sampler2D remap;      // camera size: canvas pixel
layout(binding = kUnitCompositeEmissive) uniform sampler2D gEmissive;  // canvas, a = slot + 1
void main() {
#ifdef MIRAGE_IDENTITY_REMAP  // as composite.frag's variant
    vec2 canvasPx = gl_FragCoord.xy - 0.5;
#else
    vec2 canvasPx = texelFetch(remap, ivec2(gl_FragCoord.xy), 0).xy;
#endif
    bool specular = false;
    if (canvasPx.x > -1000.0) {
        ivec2 cpi = clamp(ivec2(floor(canvasPx + 0.5)), ivec2(0), textureSize(gEmissive, 0) - 1);
        specular = texelFetch(gEmissive, cpi, 0).a > 0.5;
    }
    gl_FragDepth = specular ? 0.0 : 1.0;
}
