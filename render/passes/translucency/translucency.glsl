// Shared by translucency.comp and direct.frag: the voxel number maps of the scene's translucent
// objects (render/passes/translucency/TranslucencyPass.cpp uploads them) and the boundary
// transmittance. World metres; radiance linear W/(m^2 sr).
#ifndef MIRAGE_TRANSLUCENCY_GLSL
#define MIRAGE_TRANSLUCENCY_GLSL

// At most this many objects have a map (TranslucencyPass::kMaxObjects: the same number).
const int kMaxTranslucentObjects = 8;

// One object's map: gridOrigin.xyz = world corner of its cell (0,0,0), .w = voxel edge (m);
// gridDims.xyz = cells per axis, .w = S (its surface voxels); params.x = the medium's index of
// refraction, .y = F_t averaged over the cosine-weighted hemisphere, .z = 1 for the smooth
// lookup (translucentWeights), 0 for the nearest voxel alone, .w = the mean extinction (1/m) at
// its surface voxels' centres; offsets.x = its first cell
// in gridNumber, .y = its first surface voxel in the voxel, irradiance and radiance buffers
// (which hold 2 entries per voxel: an object's S for L_rv, then its S for L_r, from 2 * .y on),
// .z = its first entry in the tau LUT; albedoOverPi.rgb = VnmShading::radianceScale (the measured
// exit albedo over pi F_t,hemisphere, or a_eff / pi); falloff.rgb = k of the
// kernel e^{-k tau} (VoxelNumberMap::falloff).
struct TranslucentObjectGpu {
    vec4 gridOrigin;
    ivec4 gridDims;
    vec4 params;
    ivec4 offsets;
    vec4 albedoOverPi;
    vec4 falloff;
};
// objectCount.x objects; gridNumber: per cell (x fastest) the object's surface voxel or -1.
layout(std430, binding = kBindingTranslucentGrid) readonly buffer TranslucentGridBlock {
    ivec4 objectCount;
    TranslucentObjectGpu translucentObjects[kMaxTranslucentObjects];
    int gridNumber[];
};

// The optical thickness between every two surface voxels of each object, S x S half floats two per
// uint from the object's offsets.z on (VoxelNumberMap::tauHalf).
layout(std430, binding = kBindingTranslucentLut) readonly buffer TranslucentLutBlock {
    uint tauHalf[];
};

// tau between surface voxels i and o of an object (local numbers; lutFirst = its offsets.z).
float translucentTau(int i, int o, int S, int lutFirst) {
    uint k = uint(lutFirst) + uint(i) * uint(S) + uint(o);
    vec2 h = unpackHalf2x16(tauHalf[k >> 1u]);
    return (k & 1u) == 0u ? h.x : h.y;
}

// F_t = 1 - Fresnel reflectance of a smooth dielectric boundary of index ior at |cos| = c
// (render/raytrace/Bsdf.cpp fresnelDielectric, seen from outside).
float boundaryTransmittance(float ior, float c) {
    if (ior == 1.0) return 1.0;
    c = clamp(c, 0.0, 1.0);
    float sin2T = (1.0 - c * c) / (ior * ior);
    if (sin2T >= 1.0) return 0.0;
    float cosT = sqrt(max(0.0, 1.0 - sin2T));
    float rPar = (ior * c - cosT) / (ior * c + cosT);
    float rPerp = (c - ior * cosT) / (c + ior * cosT);
    return 1.0 - 0.5 * (rPar * rPar + rPerp * rPerp);
}

// The surface voxel of object k standing for world point p (VoxelNumberMap::surfaceVoxelAt):
// the number in p's cell (dist = 0), else the numbered cell within 2 cells whose centre is
// nearest to p (dist = that distance, m); -1 if none.
int surfaceVoxelAt(int k, vec3 p, out float dist) {
    TranslucentObjectGpu o = translucentObjects[k];
    dist = 1e30;
    ivec3 c = ivec3(floor((p - o.gridOrigin.xyz) / o.gridOrigin.w));
    ivec3 dims = o.gridDims.xyz;
    int first = o.offsets.x;
    if (any(lessThan(c, ivec3(-2))) || any(greaterThan(c, dims + 1))) return -1;
    if (all(greaterThanEqual(c, ivec3(0))) && all(lessThan(c, dims))) {
        int n = gridNumber[first + (c.z * dims.y + c.y) * dims.x + c.x];
        if (n >= 0) {
            dist = 0.0;
            return n;
        }
    }
    int best = -1;
    for (int dz = -2; dz <= 2; ++dz)
        for (int dy = -2; dy <= 2; ++dy)
            for (int dx = -2; dx <= 2; ++dx) {
                ivec3 q = c + ivec3(dx, dy, dz);
                if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, dims))) continue;
                int n = gridNumber[first + (q.z * dims.y + q.y) * dims.x + q.x];
                if (n < 0) continue;
                vec3 centre = o.gridOrigin.xyz + (vec3(q) + 0.5) * o.gridOrigin.w;
                float d = length(centre - p);
                if (d < dist) {
                    dist = d;
                    best = n;
                }
            }
    return best;
}

// The smooth lookup (VoxelNumberMap::reconstructionAt): the surface voxels of object k whose
// centres lie within kTranslucentFilterRadius voxel edges of world point p (all in the 3x3x3
// cells around p's), weighted (1 - (d / r)^2)^2 and normalised; count = how many (0: none near).
const float kTranslucentFilterRadius = 1.5;
int translucentWeights(int k, vec3 p, out int voxel[27], out float weight[27]) {
    TranslucentObjectGpu o = translucentObjects[k];
    vec3 g = (p - o.gridOrigin.xyz) / o.gridOrigin.w;
    ivec3 c = ivec3(floor(g));
    ivec3 dims = o.gridDims.xyz;
    int first = o.offsets.x;
    int count = 0;
    float sum = 0.0;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                ivec3 q = c + ivec3(dx, dy, dz);
                if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, dims))) continue;
                int n = gridNumber[first + (q.z * dims.y + q.y) * dims.x + q.x];
                if (n < 0) continue;
                float x = length(vec3(q) + 0.5 - g) / kTranslucentFilterRadius;
                if (x >= 1.0) continue;
                float w = (1.0 - x * x) * (1.0 - x * x);
                voxel[count] = n;
                weight[count] = w;
                sum += w;
                ++count;
            }
    for (int j = 0; j < count; ++j) weight[j] /= sum;
    return count;
}

// Where a ray from grid point g (grid units) along unit direction dir leaves the last surface voxel
// of object o it meets before it leaves the grid (a 3D DDA over the cells; grid units along dir
// from g, 0 if it meets none), and that voxel (-1 if none) and its cell.
float translucentLastSurfaceVoxel(TranslucentObjectGpu o, vec3 g, vec3 dir, out int voxel,
                                  out ivec3 cell) {
    ivec3 dims = o.gridDims.xyz;
    ivec3 c = ivec3(floor(g));
    ivec3 stepDir = ivec3(sign(dir));
    vec3 inv = 1.0 / max(abs(dir), vec3(1e-9));
    vec3 next = (vec3(c) + max(vec3(stepDir), vec3(0.0)) - g) / vec3(dir + vec3(1e-12));
    vec3 tMax = mix(vec3(1e30), abs(next), vec3(notEqual(stepDir, ivec3(0))));
    voxel = -1;
    cell = c;
    float tLeave = 0.0;
    if (all(greaterThanEqual(c, ivec3(0))) && all(lessThan(c, dims))) {
        voxel = gridNumber[o.offsets.x + (c.z * dims.y + c.y) * dims.x + c.x];
        if (voxel >= 0) tLeave = min(tMax.x, min(tMax.y, tMax.z));
    }
    int steps = dims.x + dims.y + dims.z + 3;
    for (int s = 0; s < steps; ++s) {
        if (tMax.x <= tMax.y && tMax.x <= tMax.z) {
            c.x += stepDir.x;
            tMax.x += inv.x;
        } else if (tMax.y <= tMax.z) {
            c.y += stepDir.y;
            tMax.y += inv.y;
        } else {
            c.z += stepDir.z;
            tMax.z += inv.z;
        }
        if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, dims))) break;
        int n = gridNumber[o.offsets.x + (c.z * dims.y + c.y) * dims.x + c.x];
        if (n >= 0) {
            voxel = n;
            cell = c;
            tLeave = min(tMax.x, min(tMax.y, tMax.z));
        }
    }
    return tLeave;
}

// How far (voxel edges) before the ray leaves the last surface voxel the chord ends (below).
const float kChordEndVoxels = 0.5;

// e^{-tau} of the chord the camera ray (unit direction dir) crosses through object k from its
// surface voxel `entry` at p (on the surface). The chord ends half a voxel before the far side
// of the last surface voxel the ray meets (surface voxels' centres lie inside the surface),
// averaged over the ray and four parallel rays half a voxel beside it (one ray alone steps with
// the voxels' staircase). Its extinction is the LUT's tau from the entry voxel to that last one
// over the distance from p to its centre (the mean along the way: cavities and the air of
// concave parts count as nothing), or the object's mean extinction at its surface voxels
// (params.w) when the ray meets no other surface voxel (near the silhouette).
float translucentChordTransmittance(int k, int entry, vec3 p, vec3 dir) {
    TranslucentObjectGpu o = translucentObjects[k];
    vec3 g = (p - o.gridOrigin.xyz) / o.gridOrigin.w;  // grid units
    int exitVoxel;
    ivec3 exitCell;
    float tLeave = translucentLastSurfaceVoxel(o, g, dir, exitVoxel, exitCell);
    float sigma = o.params.w;
    if (exitVoxel >= 0 && exitVoxel != entry) {
        vec3 centre = o.gridOrigin.xyz + (vec3(exitCell) + 0.5) * o.gridOrigin.w;
        sigma = translucentTau(entry, exitVoxel, o.gridDims.w, o.offsets.z) /
                max(distance(centre, p), 0.5 * o.gridOrigin.w);
    }
    vec3 u = normalize(cross(dir, abs(dir.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0)));
    vec3 w = cross(dir, u);
    const vec2 kBeside[4] = vec2[4](vec2(0.5, 0.0), vec2(-0.5, 0.0), vec2(0.0, 0.5), vec2(0.0, -0.5));
    float sum = exp(-sigma * max(tLeave - kChordEndVoxels, 0.0) * o.gridOrigin.w);
    for (int j = 0; j < 4; ++j) {
        int v;
        ivec3 cl;
        float t = translucentLastSurfaceVoxel(o, g + kBeside[j].x * u + kBeside[j].y * w, dir, v, cl);
        sum += exp(-sigma * max(t - kChordEndVoxels, 0.0) * o.gridOrigin.w);
    }
    return sum / 5.0;
}

// The translucent object and surface voxel standing for world point p: the object whose map has
// a surface voxel nearest to p (objects may share cells only where they touch). False if none.
bool translucentVoxelAt(vec3 p, out int object, out int voxel) {
    object = -1;
    voxel = -1;
    float best = 1e30;
    for (int k = 0; k < objectCount.x; ++k) {
        float d;
        int n = surfaceVoxelAt(k, p, d);
        if (n >= 0 && d < best) {
            best = d;
            object = k;
            voxel = n;
        }
    }
    return voxel >= 0;
}

#endif
