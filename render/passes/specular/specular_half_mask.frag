#version 450 core
#include "common.glsl"
// Depth mask of the half-resolution specular lighting (specular_light.frag MIRAGE_SPECULAR_HALF):
// depth 0 where any canvas pixel of the half pixel's 2x2 block is specular (GBuf_refl's emissive
// a = 1), 1 elsewhere; as specular_mask.frag, so llvmpipe's early depth test skips blocks without
// one.
layout(binding = kUnitSpecLightReflFirst + 3) uniform sampler2D reflEmissive;
void main() {
    ivec2 block = 2 * ivec2(gl_FragCoord.xy), size = textureSize(reflEmissive, 0);
    float any = 0.0;
    for (int i = 0; i < 4; ++i) {
        ivec2 c = block + ivec2(i & 1, i >> 1);
        if (all(lessThan(c, size))) any = max(any, texelFetch(reflEmissive, c, 0).a);
    }
    gl_FragDepth = any >= 0.5 ? 0.0 : 1.0;
}
