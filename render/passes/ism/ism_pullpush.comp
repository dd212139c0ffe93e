#version 450 core
#include "common.glsl"
// Pull-push hole filling of the imperfect shadow maps (Ritschel et al. 2008, Sec. 3.3, after
// Marroquim et al. 2007): a VPL's tile is splatted from ~1,000 points, and where the points of a
// surface leave gaps the VPL sees through it. Per tile, a pyramid of 2x2 reductions (pull):
// each texel's depth is the coverage-weighted mean of its children's, its coverage the mean of
// theirs (1 for a splatted atlas texel, 0 for an empty one). Then coarse to fine (push), a texel
// with nothing in it takes its parent's depth when the parent is covered at least minCoverage,
// so a gap inside a splatted surface closes while open space beside a silhouette, whose parent
// is mostly empty, stays open. Tiles are powers of two apart at every level used
// (IsmPass::pullPushLevels), so a texel's children and parent lie in its own tile.
// Depths in metres; the atlas stores them as float bits in r32ui, +inf (0x7F800000) = empty.
layout(local_size_x = 8, local_size_y = 8) in;
layout(r32ui, binding = kImageIsmAll) uniform uimage2D atlas;
layout(rg32f, binding = kImageIsmPyramidSrc) uniform readonly image2D src;  // rg: depth, coverage
layout(rg32f, binding = kImageIsmPyramidDst) uniform image2D dst;
// 0: pull the atlas into dst (level 1); 1: pull src (level L - 1) into dst (level L);
// 2: push src (level L + 1) into the empty texels of dst (level L); 3: push src (level 1) into
// the empty texels of the atlas.
uniform int mode;
uniform ivec2 levelSize;  // texels of the level written
uniform float minCoverage;

const uint kEmpty = 0x7F800000u;

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(t, levelSize))) return;
    if (mode == 0 || mode == 1) {
        float sumD = 0.0, sumC = 0.0;
        for (int k = 0; k < 4; ++k) {
            ivec2 c = 2 * t + ivec2(k & 1, k >> 1);
            if (mode == 0) {
                uint bits = imageLoad(atlas, c).r;
                if (bits >= kEmpty) continue;
                sumD += uintBitsToFloat(bits);
                sumC += 1.0;
            } else {
                vec2 v = imageLoad(src, c).rg;
                sumD += v.x * v.y;
                sumC += v.y;
            }
        }
        imageStore(dst, t, vec4(sumC > 0.0 ? sumD / sumC : 0.0, 0.25 * sumC, 0.0, 0.0));
        return;
    }
    vec2 parent = imageLoad(src, t / 2).rg;
    if (parent.y < minCoverage) return;
    if (mode == 2) {
        if (imageLoad(dst, t).g == 0.0) imageStore(dst, t, vec4(parent, 0.0, 0.0));
    } else if (imageLoad(atlas, t).r >= kEmpty) {
        imageStore(atlas, t, uvec4(floatBitsToUint(parent.x)));
    }
}
