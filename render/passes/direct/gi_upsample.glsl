// Joint bilateral upsampling of the filtered, temporally smoothed indirect light (filter.frag,
// gather resolution) to a canvas pixel: the 2 x 2 gather pixels around it, weighted bilinearly
// and by geometry (position / normal match with the pixel's surface). Each gather pixel's depth,
// normal and light come packed by filter.frag in one texel (llvmpipe pays per texel read, and
// this reads 4 gather pixels for each canvas pixel); its point is rebuilt on its canvas pixel's
// ray. #include after common.glsl; direct.frag adds the result to the direct light, so that the
// GI solutions L_rv and L_r come from one full-screen pass.
#ifndef MIRAGE_GI_UPSAMPLE_GLSL
#define MIRAGE_GI_UPSAMPLE_GLSL

layout(binding = kUnitDirectGatherLight) uniform usampler2D gatherLight;  // L_rv, L_r, depth, normal
uniform int gatherScale;  // the indirect light is at 1/gatherScale of the canvas per axis
// World direction of canvas pixel (x, y)'s ray, scaled to camera-frame depth 1:
// rayFromPixel * vec3(x, y, 1) (R^T K^-1 on the canvas, pixel centres at integers).
uniform mat3 rayFromPixel;

// The indirect light at canvas pixel px with surface point p (world, m) and unit normal n:
// L_rv into iRv, L_r into iR (0 where no gather pixel around it matches).
void upsampleIndirect(ivec2 px, ivec2 canvasSize, vec3 p, vec3 n, out vec3 iRv, out vec3 iR) {
    float camDist = length(p - cameraPos.xyz);
    // The plane test's distance of a gather point Q = cameraPos + z (rayFromPixel (x, y, 1)) from
    // p's tangent plane, dot(Q - p, n), is z (x nx + y ny + n1) - np: linear in the gather
    // pixel's (x, y), with these four per pixel (a few operations per tap instead of a 3 x 3
    // product and a dot product).
    float nx = dot(rayFromPixel[0], n), ny = dot(rayFromPixel[1], n);
    float n1 = dot(rayFromPixel[2], n), np = dot(p - cameraPos.xyz, n);
    float invTolerance = 1.0 / max(0.01 * camDist, 1e-4);
    ivec2 lowSize = textureSize(gatherLight, 0);
    vec2 f = canvasToGather(vec2(px), gatherScale);  // p in gather pixel coordinates
    ivec2 c0 = ivec2(floor(f));
    vec2 fr = f - vec2(c0);
    vec3 sumRv = vec3(0.0), sumR = vec3(0.0);
    float wsum = 0.0;
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        ivec2 q = clamp(c0 + o, ivec2(0), lowSize - 1);
        uvec4 L = texelFetch(gatherLight, q, 0);
        float zq = unpackHalf2x16(L.w).x;
        if (zq <= 0.0) continue;  // no surface there
        vec3 nq = unpackNormalOct8(L.w >> 16);
        vec2 cq = vec2(gatherCanvasPixel(q, gatherScale, canvasSize));
        float planeDist = abs(zq * (cq.x * nx + cq.y * ny + n1) - np) * invTolerance;
        float cs = max(dot(n, nq), 0.0);
        cs *= cs;
        cs *= cs;
        cs *= cs;
        cs *= cs;
        float geom = cs / (1.0 + planeDist * planeDist * 4.0);
        float bil = (o.x == 1 ? fr.x : 1.0 - fr.x) * (o.y == 1 ? fr.y : 1.0 - fr.y);
        float w = geom * (bil + 1e-3);  // a rejected bilinear tap leaves the others in charge
        vec2 l0 = unpackHalf2x16(L.x), l1 = unpackHalf2x16(L.y), l2 = unpackHalf2x16(L.z);
        sumRv += w * vec3(l0, l1.x);
        sumR += w * vec3(l1.y, l2);
        wsum += w;
    }
    iRv = wsum > 1e-6 ? sumRv / wsum : vec3(0.0);
    iR = wsum > 1e-6 ? sumR / wsum : vec3(0.0);
}

#endif
