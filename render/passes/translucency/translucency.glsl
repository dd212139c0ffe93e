// Shared by translucency.comp and direct.frag: the SSBOs of the first translucent object's voxel
// number map (render/passes/translucency/TranslucencyPass.cpp uploads them) and the boundary
// transmittance. World metres; radiance linear W/(m^2 sr).
#ifndef MIRAGE_TRANSLUCENCY_GLSL
#define MIRAGE_TRANSLUCENCY_GLSL

// The grid of the voxel number map: gridOrigin.xyz = world corner of cell (0,0,0), .w = voxel
// edge (m); gridDims.xyz = cells per axis, .w = S (surface voxels); gridParams.x = the medium's
// index of refraction. gridNumber: per cell (x fastest) its surface voxel or -1.
layout(std430, binding = kBindingTranslucentGrid) readonly buffer TranslucentGridBlock {
    vec4 gridOrigin;
    ivec4 gridDims;
    vec4 gridParams;
    int gridNumber[];
};

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

// The surface voxel standing for world point p (VoxelNumberMap::surfaceVoxelAt): the number in
// p's cell, else the numbered cell within 2 cells whose centre is nearest to p; -1 if none.
int surfaceVoxelAt(vec3 p) {
    ivec3 c = ivec3(floor((p - gridOrigin.xyz) / gridOrigin.w));
    ivec3 dims = gridDims.xyz;
    if (all(greaterThanEqual(c, ivec3(0))) && all(lessThan(c, dims))) {
        int n = gridNumber[(c.z * dims.y + c.y) * dims.x + c.x];
        if (n >= 0) return n;
    }
    int best = -1;
    float bestD = 1e30;
    for (int dz = -2; dz <= 2; ++dz)
        for (int dy = -2; dy <= 2; ++dy)
            for (int dx = -2; dx <= 2; ++dx) {
                ivec3 q = c + ivec3(dx, dy, dz);
                if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, dims))) continue;
                int n = gridNumber[(q.z * dims.y + q.y) * dims.x + q.x];
                if (n < 0) continue;
                vec3 centre = gridOrigin.xyz + (vec3(q) + 0.5) * gridOrigin.w;
                float d = length(centre - p);
                if (d < bestD) {
                    bestD = d;
                    best = n;
                }
            }
    return best;
}

#endif
