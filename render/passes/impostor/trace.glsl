// Reflected / refracted ray tracing against a specular object's surroundings (Knecht 2013
// Sec. 3.2 / 4.1, Popescu et al. 2006 reflected-scene impostors). #include after common.glsl.
//
//   SurroundingHit traceSurroundings(int specularSlot, vec3 rayOrigin, vec3 rayDir);
//
// specularSlot indexes GpuScene::specularDraws(); the object's own geometry is not in its
// impostors. rayOrigin / rayDir are world (metres), rayDir unit. Built by ImpostorPass, bound by
// ImpostorPass::bindForTracing(). Uses ONLY the texture units kUnitImpostor* (16..25) and the
// uniform-block binding kBindingImpostorHeader (render/bindings.glsl).
//
// Two methods, chosen by RendererOptions::impostorCubeMapBaseline
// (GpuImpostorHeader::cubeMapBaseline):
// - baseline: a G-buffer cube map rendered from the object's bounding-sphere centre c, looked up
//   by the ray DIRECTION only (classic environment mapping: exact only for a ray starting at c or
//   for infinitely distant surroundings).
// - impostors: one box-bounded depth impostor per surrounding draw item (a billboard facing c,
//   storing per texel the offset of the surface from the billboard plane plus G-buffer
//   attributes); the ray is clipped to the box, a coarse linear search finds the first crossing
//   of the height field and `refineSteps` secant (regula falsi) steps refine it; nearest hit
//   wins. Planar items (floors, table tops, walls) are impostors whose plane IS the item's plane:
//   intersected exactly, attributes looked up. Non-planar items that enclose the object or reach
//   behind the billboard plane seen from c (a room) go to a depth cube map from c, searched the
//   same way along the ray (distance impostor). See docs/impostors.md.
#ifndef MIRAGE_IMPOSTOR_TRACE_GLSL
#define MIRAGE_IMPOSTOR_TRACE_GLSL

layout(binding = kUnitImpostorCubePosition) uniform sampler2DArray impCubePosition;  // xyz world (m), w = origin (0 empty)
layout(binding = kUnitImpostorCubeNormal) uniform sampler2DArray impCubeNormal;    // xyz world normal, w = roughness
layout(binding = kUnitImpostorCubeAlbedo) uniform sampler2DArray impCubeAlbedo;    // rgb linear base colour, a = metallic
layout(binding = kUnitImpostorCubeEmissive) uniform sampler2DArray impCubeEmissive;  // rgb linear emitted radiance
layout(binding = kUnitImpostorDepth) uniform sampler2DArray impDepth;     // r = offset along axisW (m), g = origin;
                                                          // r = 1e30, g = 0 where empty (linear)
layout(binding = kUnitImpostorNormal) uniform sampler2DArray impNormal;    // xyz world normal, w = roughness
layout(binding = kUnitImpostorAlbedo) uniform sampler2DArray impAlbedo;    // rgb linear base colour, a = metallic
layout(binding = kUnitImpostorEmissive) uniform sampler2DArray impEmissive;  // rgb linear emitted radiance

#include "impostor_types.glsl"

// The tables, as llvmpipe reads them fastest: it reads a storage buffer lane by lane (even at an
// index every lane shares), a uniform block at a shared address once, and a buffer texture with
// one gather per texel. So the header is a uniform block over the objects buffer's first 32
// bytes, and records and objects are read as RGBA32F texels of their std430 layout (a
// GpuImpostor is 5 texels, a GpuImpostorObject 3 after the header's 2).
layout(std140, binding = kBindingImpostorHeader) uniform ImpostorHeader { GpuImpostorHeader impHeader; };
layout(binding = kUnitImpostorRecords) uniform samplerBuffer impRecordTexels;
layout(binding = kUnitImpostorObjects) uniform samplerBuffer impObjectTexels;

GpuImpostor impostorAt(int i) {
    vec4 a = texelFetch(impRecordTexels, 5 * i), b = texelFetch(impRecordTexels, 5 * i + 1);
    vec4 c = texelFetch(impRecordTexels, 5 * i + 2), d = texelFetch(impRecordTexels, 5 * i + 3);
    ivec4 e = floatBitsToInt(texelFetch(impRecordTexels, 5 * i + 4));
    GpuImpostor I;
    I.centre = a.xyz;
    I.layer = floatBitsToInt(a.w);
    I.axisU = b.xyz;
    I.halfU = b.w;
    I.axisV = c.xyz;
    I.halfV = c.w;
    I.axisW = d.xyz;
    I.halfW = d.w;
    I.kind = e.x;
    I.drawIndex = e.y;
    I.pad0 = 0;
    I.pad1 = 0;
    return I;
}

GpuImpostorObject impostorObjectAt(int slot) {
    vec4 a = texelFetch(impObjectTexels, 2 + 3 * slot);
    ivec4 b = floatBitsToInt(texelFetch(impObjectTexels, 2 + 3 * slot + 1));
    vec4 c = texelFetch(impObjectTexels, 2 + 3 * slot + 2);
    GpuImpostorObject O;
    O.centre = a.xyz;
    O.radius = a.w;
    O.firstImpostor = b.x;
    O.impostorCount = b.y;
    O.baselineCubeLayer = b.z;
    O.enclosingCubeLayer = b.w;
    O.enclosingReach = c.x;
    O.pad0 = 0.0;
    O.pad1 = 0.0;
    O.pad2 = 0.0;
    return O;
}

struct SurroundingHit {
    bool hit;        // false: the ray leaves the modelled scene (the consumer uses L_env)
    vec3 position;   // world, metres
    vec3 normal;     // world unit normal, facing the ray origin
    vec3 albedo;     // linear base colour
    float roughness;
    float metallic;
    vec3 emissive;   // linear emitted radiance
    int origin;      // ORIGIN_REAL or ORIGIN_VIRTUAL
};

const float IMP_EMPTY = 1e29;  // depth values above this are "no surface"

SurroundingHit impNoHit() {
    SurroundingHit h;
    h.hit = false;
    h.position = vec3(0.0);
    h.normal = vec3(0.0, 1.0, 0.0);
    h.albedo = vec3(0.0);
    h.roughness = 1.0;
    h.metallic = 0.0;
    h.emissive = vec3(0.0);
    h.origin = ORIGIN_NONE;
    return h;
}

// Cube faces as rendered by ImpostorPass: forward axis and the up vector given to lookAt.
vec3 impFaceForward(int f) {
    return f == 0 ? vec3(1, 0, 0)
         : f == 1 ? vec3(-1, 0, 0)
         : f == 2 ? vec3(0, 1, 0)
         : f == 3 ? vec3(0, -1, 0)
         : f == 4 ? vec3(0, 0, 1)
                  : vec3(0, 0, -1);
}
vec3 impFaceUp(int f) {
    return f == 2 ? vec3(0, 0, 1) : f == 3 ? vec3(0, 0, -1) : vec3(0, -1, 0);
}

// Texel of a cube (6 layers from `firstLayer`) in world direction d (need not be unit). Each
// face's right and up axes are the world axes lookAt(forward, impFaceUp) gives it, written out:
// the same texel as projecting on S = normalize(cross(F, up)), U = cross(S, F), without the
// per-sample normalize and cross products (the enclosing search calls this ~20 times a ray).
ivec3 impCubeTexel(vec3 d, int firstLayer) {
    vec3 a = abs(d);
    bool xMajor = a.x >= a.y && a.x >= a.z, yMajor = !xMajor && a.y >= a.z;
    // (right, up, forward) coordinates of d on its face.
    vec3 m = xMajor   ? (d.x >= 0.0 ? vec3(-d.z, -d.y, d.x) : vec3(d.z, -d.y, -d.x))
           : yMajor   ? (d.y >= 0.0 ? vec3(d.x, d.z, d.y) : vec3(d.x, -d.z, -d.y))
                      : (d.z >= 0.0 ? vec3(d.x, -d.y, d.z) : vec3(-d.x, -d.y, -d.z));
    int f = xMajor ? (d.x >= 0.0 ? 0 : 1) : yMajor ? (d.y >= 0.0 ? 2 : 3) : (d.z >= 0.0 ? 4 : 5);
    float z = max(m.z, 1e-20);
    vec2 ndc = clamp(m.xy / z, -1.0, 1.0);
    int res = int(impHeader.cubeResolution);
    ivec2 px = clamp(ivec2((ndc * 0.5 + 0.5) * float(res)), ivec2(0), ivec2(res - 1));
    return ivec3(px, firstLayer + f);
}

void impFillFromCube(inout SurroundingHit h, ivec3 t, vec3 rayOrigin) {
    vec4 n = texelFetch(impCubeNormal, t, 0);
    vec4 a = texelFetch(impCubeAlbedo, t, 0);
    vec3 nn = dot(n.xyz, n.xyz) > 1e-12 ? normalize(n.xyz) : vec3(0.0, 1.0, 0.0);
    if (dot(nn, rayOrigin - h.position) < 0.0) nn = -nn;
    h.normal = nn;
    h.roughness = n.w;
    h.albedo = a.rgb;
    h.metallic = a.a;
    h.emissive = texelFetch(impCubeEmissive, t, 0).rgb;
}

// Baseline: the stored surface in direction rayDir from the cube centre (direction only).
SurroundingHit impTraceCube(GpuImpostorObject obj, vec3 o, vec3 d) {
    SurroundingHit h = impNoHit();
    ivec3 t = impCubeTexel(d, obj.baselineCubeLayer);
    vec4 p = texelFetch(impCubePosition, t, 0);
    if (p.w < 0.5) return h;
    h.hit = true;
    h.position = p.xyz;
    h.origin = int(p.w + 0.5);
    impFillFromCube(h, t, o);
    return h;
}

// Signed distance of ray point x behind the enclosing cube's stored surface (>= 0: behind).
float impEnclosingH(vec3 c, int layer, vec3 x, out ivec3 texel) {
    vec3 r = x - c;
    float len = length(r);
    texel = impCubeTexel(len > 1e-9 ? r : vec3(0.0, 0.0, 1.0), layer);
    vec4 p = texelFetch(impCubePosition, texel, 0);
    if (p.w < 0.5) return -1e30;
    return len - length(p.xyz - c);
}

// Enclosing items (distance impostor from c): first crossing along the ray within tBest.
bool impTraceEnclosing(GpuImpostorObject obj, vec3 o, vec3 d, inout float tBest,
                       out ivec3 texel) {
    texel = ivec3(0);
    if (obj.enclosingCubeLayer < 0) return false;
    vec3 c = obj.centre;
    float t1 = min(obj.enclosingReach, tBest);
    int n = max(impHeader.coarseSamples, 1) * 2;
    ivec3 ta_tex, tb_tex;
    float ta = 0.0, ha = impEnclosingH(c, obj.enclosingCubeLayer, o, ta_tex);
    float tb = 0.0, hb = ha;
    bool found = false;
    for (int i = 1; i <= n && !found; ++i) {
        tb = t1 * float(i) / float(n);
        hb = impEnclosingH(c, obj.enclosingCubeLayer, o + tb * d, tb_tex);
        if (ha < 0.0 && hb >= 0.0) found = true;
        else {
            ta = tb;
            ha = hb;
        }
    }
    if (!found) return false;
    // Refinement: Newton steps on the tangent plane stored at the current texel (exact for
    // planar walls), kept inside the bracket [ta, tb]; regula falsi when the plane step leaves it.
    // The stored point and normal at t: each step's are the ones the previous step read at its
    // tm (= this t), carried over instead of looked up again.
    float t = ha > -IMP_EMPTY ? ta + (tb - ta) * ha / (ha - hb) : tb;
    ivec3 cur_tex = impCubeTexel(o + t * d - c, obj.enclosingCubeLayer);
    vec4 q = texelFetch(impCubePosition, cur_tex, 0);
    vec3 qn = texelFetch(impCubeNormal, cur_tex, 0).xyz;
    for (int s = 0; s < impHeader.refinementSteps; ++s) {
        float dn = dot(d, qn);
        float tm = ha > -IMP_EMPTY ? ta + (tb - ta) * ha / (ha - hb) : 0.5 * (ta + tb);
        if (q.w > 0.5 && abs(dn) > 1e-4) {
            float tp = dot(q.xyz - o, qn) / dn;
            if (tp >= ta && tp <= tb) tm = tp;
        }
        if (abs(tm - t) < 1e-7 * max(tm, 1.0) && s > 0) break;  // converged
        ivec3 tm_tex;
        float hm = impEnclosingH(c, obj.enclosingCubeLayer, o + tm * d, tm_tex);
        // Behind / in front of the stored tangent plane, consistent with the plane step (c's
        // side is in front).
        vec4 qm = texelFetch(impCubePosition, tm_tex, 0);
        vec3 nm = texelFetch(impCubeNormal, tm_tex, 0).xyz;
        if (qm.w > 0.5 && dot(nm, nm) > 1e-12)
            hm = dot(o + tm * d - qm.xyz, nm) * (dot(c - qm.xyz, nm) > 0.0 ? -1.0 : 1.0);
        if (hm < 0.0) {
            ta = tm;
            ha = hm;
        } else {
            tb = tm;
            hb = hm;
            tb_tex = tm_tex;
        }
        t = tm;
        cur_tex = tm_tex;
        q = qm;
        qn = nm;
    }
    if (!(t > 0.0) || t >= tBest) return false;
    ivec3 final_tex = cur_tex;  // q, qn: the stored point and normal there
    vec3 x = o + t * d;
    if (q.w < 0.5) return false;  // an empty texel
    // A distance cube stores one surface per direction from c: a ray that passes over an edge
    // (a wall's top) lands "behind" it in a direction where the wall is. Accept only points on
    // the stored surface: within two texel footprints of the texel's point and one footprint of
    // its tangent plane.
    float footprint = length(x - c) * 2.0 / impHeader.cubeResolution + 1e-3;
    if (length(x - q.xyz) > 2.0 * footprint) return false;
    if (dot(qn, qn) > 1e-12 && abs(dot(x - q.xyz, normalize(qn))) > footprint) return false;
    tBest = t;
    texel = final_tex;
    return true;
}

// Height-field offset along axisW at box-local (u, v) metres, bilinear; > IMP_EMPTY if empty.
float impDepthAt(GpuImpostor I, vec2 q) {
    vec2 uv = q / vec2(I.halfU, I.halfV) * 0.5 + 0.5;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return 1e30;
    return textureLod(impDepth, vec3(uv, float(I.layer)), 0.0).r;
}
ivec3 impTexel(GpuImpostor I, vec2 q) {
    vec2 uv = q / vec2(I.halfU, I.halfV) * 0.5 + 0.5;
    int res = int(impHeader.impostorResolution);
    return ivec3(clamp(ivec2(uv * float(res)), ivec2(0), ivec2(res - 1)), I.layer);
}

// One impostor: nearest hit closer than tBest; on success updates tBest and the texel.
bool impTraceOne(GpuImpostor I, vec3 o, vec3 d, inout float tBest, out ivec3 texel) {
    texel = ivec3(0);
    vec3 rel = o - I.centre;
    vec3 ro = vec3(dot(rel, I.axisU), dot(rel, I.axisV), dot(rel, I.axisW));
    vec3 rd = vec3(dot(d, I.axisU), dot(d, I.axisV), dot(d, I.axisW));
    vec3 e = vec3(I.halfU, I.halfV, I.halfW);
    if (I.kind == kImpostorPlane) {
        // Planar item: exact ray-plane intersection; parallel rays never hit it.
        if (abs(rd.z) < 1e-7) return false;
        float t = -ro.z / rd.z;
        if (!(t > 1e-6) || t >= tBest) return false;
        vec2 q = ro.xy + t * rd.xy;
        if (any(greaterThan(abs(q), e.xy))) return false;
        ivec3 tx = impTexel(I, q);
        if (texelFetch(impDepth, tx, 0).g < 0.5) return false;  // a hole in the item
        tBest = t;
        texel = tx;
        return true;
    }
    // Clip the ray to the box (slabs); an axis the ray is parallel to must contain the origin.
    float t0 = 0.0, t1 = tBest;
    for (int i = 0; i < 3; ++i) {
        if (abs(rd[i]) < 1e-9) {
            if (abs(ro[i]) > e[i]) return false;
            continue;
        }
        float a = (-e[i] - ro[i]) / rd[i], b = (e[i] - ro[i]) / rd[i];
        t0 = max(t0, min(a, b));
        t1 = min(t1, max(a, b));
    }
    if (!(t0 < t1)) return false;
    // Coarse linear search for the first step from in front of the stored surface (seen from the
    // specular object) to behind it: h = ray offset along W - stored offset.
    int n = max(impHeader.coarseSamples, 1);
    float dt = (t1 - t0) / float(n);
    float ta = t0;
    float ha = ro.z + ta * rd.z - impDepthAt(I, ro.xy + ta * rd.xy);
    float tb = ta, hb = ha;
    bool found = false;
    for (int i = 1; i <= n && !found; ++i) {
        tb = t0 + dt * float(i);
        hb = ro.z + tb * rd.z - impDepthAt(I, ro.xy + tb * rd.xy);
        if (ha < 0.0 && hb >= 0.0) found = true;
        else {
            ta = tb;
            ha = hb;
        }
    }
    if (!found) return false;
    // A depth impostor stores one layer: a ray that enters the silhouette far behind the front
    // surface passes behind the item. Accept only a crossing within one coarse step's travel
    // along W plus two texels.
    float texelM = 2.0 * max(e.x, e.y) / impHeader.impostorResolution;
    float thickness = abs(rd.z) * dt + 2.0 * texelM;
    if (ha < -IMP_EMPTY && hb > thickness) return false;
    // Refinement: Newton steps on the tangent plane of the height field at the current estimate
    // (stored normal, bilinear depth), kept inside the bracket [ta, tb]; regula falsi otherwise.
    // Each step's depth at t is the depth the previous step sampled at its tm (= this t): kept
    // in dq, one bilinear lookup per step.
    float t = ha > -IMP_EMPTY && hb - ha > 0.0 ? ta + (tb - ta) * ha / (ha - hb) : tb;
    float dq = impDepthAt(I, ro.xy + t * rd.xy);
    for (int s = 0; s < impHeader.refinementSteps; ++s) {
        vec2 qc = ro.xy + t * rd.xy;
        vec3 n = texelFetch(impNormal, impTexel(I, qc), 0).xyz;
        vec3 nl = vec3(dot(n, I.axisU), dot(n, I.axisV), dot(n, I.axisW));
        float dn = dot(rd, nl);
        float tm = ha > -IMP_EMPTY ? ta + (tb - ta) * ha / (ha - hb) : 0.5 * (ta + tb);
        if (dq < IMP_EMPTY && abs(dn) > 1e-4) {
            float tp = dot(vec3(qc, dq) - ro, nl) / dn;
            if (tp >= ta && tp <= tb) tm = tp;
        }
        dq = impDepthAt(I, ro.xy + tm * rd.xy);
        float hm = ro.z + tm * rd.z - dq;
        if (hm < 0.0) {
            ta = tm;
            ha = hm;
        } else {
            tb = tm;
            hb = hm;
        }
        t = tm;
    }
    if (!(t >= 0.0) || t >= tBest) return false;
    ivec3 tx = impTexel(I, ro.xy + t * rd.xy);
    if (texelFetch(impDepth, tx, 0).g < 0.5) tx = impTexel(I, ro.xy + tb * rd.xy);
    if (texelFetch(impDepth, tx, 0).g < 0.5) return false;
    tBest = t;
    texel = tx;
    return true;
}

SurroundingHit traceSurroundings(int specularSlot, vec3 rayOrigin, vec3 rayDir) {
    SurroundingHit h = impNoHit();
    if (specularSlot < 0 || specularSlot >= impHeader.objectCount) return h;
    if (!allFinite(rayOrigin) || !allFinite(rayDir) || dot(rayDir, rayDir) < 1e-12) return h;
    vec3 d = normalize(rayDir);
    GpuImpostorObject obj = impostorObjectAt(specularSlot);
    if (impHeader.cubeMapBaseline == 1) return impTraceCube(obj, rayOrigin, d);

    float tBest = 1e30;
    int best = -1;  // impostor index, or -2 = enclosing cube
    ivec3 bestTexel = ivec3(0);
    ivec3 tx;
    if (impTraceEnclosing(obj, rayOrigin, d, tBest, tx)) {
        best = -2;
        bestTexel = tx;
    }
    for (int k = 0; k < obj.impostorCount; ++k) {
        int idx = obj.firstImpostor + k;
        if (impTraceOne(impostorAt(idx), rayOrigin, d, tBest, tx)) {
            best = idx;
            bestTexel = tx;
        }
    }
    if (best == -1) return h;
    h.hit = true;
    h.position = rayOrigin + tBest * d;
    if (best == -2) {
        h.origin = int(texelFetch(impCubePosition, bestTexel, 0).w + 0.5);
        impFillFromCube(h, bestTexel, rayOrigin);
        return h;
    }
    vec4 n = texelFetch(impNormal, bestTexel, 0);
    vec4 a = texelFetch(impAlbedo, bestTexel, 0);
    vec3 nn = dot(n.xyz, n.xyz) > 1e-12 ? normalize(n.xyz) : -d;
    if (dot(nn, d) > 0.0) nn = -nn;
    h.normal = nn;
    h.roughness = n.w;
    h.albedo = a.rgb;
    h.metallic = a.a;
    h.emissive = texelFetch(impEmissive, bestTexel, 0).rgb;
    h.origin = int(texelFetch(impDepth, bestTexel, 0).g + 0.5);
    return h;
}

#endif
