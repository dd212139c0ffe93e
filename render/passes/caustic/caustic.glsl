// Helpers shared by the caustic passes (include after common.glsl): the photon G-buffers' texel
// decoding and the photons' footprint (caustic_splat.comp, photon_grid_*.comp), the routing of a
// caustic's irradiance into the two GI solutions (caustic_resolve.frag for the camera's pixels,
// the photon gather of specular_light.frag for the reflected / refracted hits), and the hashed
// cell of the world-space photon grid. World metres, linear W and W/m^2.
#ifndef MIRAGE_CAUSTIC_GLSL
#define MIRAGE_CAUSTIC_GLSL

// Photon hit texel: xyz world receiver hit, w = 4 x hit origin + real-path visibility (0..1)
// + 2 for a photon scattered over a rough surface's lobe (photon_gbuffer.frag).
int photonHitOrigin(vec4 hit) { return int(floor((hit.w + 0.5) / 4.0)); }
float photonRealVisibility(vec4 hit) {
    float v = hit.w - 4.0 * float(photonHitOrigin(hit));
    return v > 1.5 ? v - 2.0 : v;
}
bool photonFromRoughLobe(vec4 hit) { return hit.w - 4.0 * float(photonHitOrigin(hit)) > 1.5; }

// A photon texel's powers for L_rv (power x visibility through all occluders) and for L_r (power
// x real-path visibility: nonzero only when the light and the specular object are real). False
// when there is no photon (no specular surface at the texel, or it left the modelled scene) or
// it carries nothing.
bool photonPowers(vec4 hit, vec4 power, out vec3 powerRv, out vec3 powerR) {
    powerRv = vec3(0.0);
    powerR = vec3(0.0);
    int origin = photonHitOrigin(hit);
    if (origin == ORIGIN_NONE) return false;
    float realVis = photonRealVisibility(hit);
    powerRv = power.rgb * power.a;
    powerR = power.rgb * realVis;
    return max(max(powerRv.r, powerRv.g), max(powerRv.b, max(powerR.r, max(powerR.g, powerR.b)))) >
           0.0;
}

// The photon's footprint on its receiver (Wyman 2008): the largest distance to a neighbouring
// photon's hit on the same surface (the rays' divergence from the light through the object).
// 0 when no neighbour lies within kMaxPhotonSpacing (an isolated photon).
const float kMaxPhotonSpacing = 0.25;  // m: neighbours farther apart lie on another surface
float photonSpacing(sampler2DArray hits, ivec3 t, int mapSize, vec3 hitPos) {
    float spacing = 0.0;
    const ivec2 nb[4] = ivec2[4](ivec2(1, 0), ivec2(-1, 0), ivec2(0, 1), ivec2(0, -1));
    for (int k = 0; k < 4; ++k) {
        ivec2 q = t.xy + nb[k];
        if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, ivec2(mapSize)))) continue;
        vec4 h = texelFetch(hits, ivec3(q, t.z), 0);
        if (photonHitOrigin(h) == ORIGIN_NONE) continue;
        float dd = distance(h.xyz, hitPos);
        if (dd < kMaxPhotonSpacing) spacing = max(spacing, dd);
    }
    return spacing;
}

// Knecht 2013 Eqs. 12-14: the caustic irradiance eRv (every photon) and eR (photons whose light
// and specular object are real) reflected by a receiver of base colour `albedo` (Lambert:
// albedo x (1 - metallic) / pi). L_rv gets every caustic; L_r only on a REAL receiver.
void causticRadiance(vec3 eRv, vec3 eR, vec3 albedo, float metallic, bool receiverReal,
                     out vec3 rv, out vec3 r) {
    vec3 brdf = albedo * (1.0 - clamp(metallic, 0.0, 1.0)) / PI;
    rv = brdf * eRv;
    r = receiverReal ? brdf * eR : vec3(0.0);
}

// The world-space photon grid: cubic cells of cellSize m (2 x the largest kernel radius), hashed
// into kPhotonGridCells buckets (Teschner et al. 2003's primes); cells that share a bucket share
// its photon list (the distance test sorts them out).
int photonBucket(ivec3 cell) {
    uint h = uint(cell.x) * 73856093u ^ uint(cell.y) * 19349663u ^ uint(cell.z) * 83492791u;
    return int(h & uint(kPhotonGridCells - 1));
}
int photonBucketAt(vec3 x, float cellSize) { return photonBucket(ivec3(floor(x / cellSize))); }

// A photon's level within its bucket, from its photon-map texel t: the coarsest lattice of
// stride 2^(kPhotonGridLevels - 1 - l) texels (16, 8, 4, 2, 1) that holds t. Levels 0..l of a
// bucket together are its photons on the lattice of stride photonLevelStride(l): a stratified
// subsample of the map (1/256, 1/64, 1/16, 1/4 of it, then all), fixed by the texels alone.
int photonLevel(ivec2 t) {
    for (int l = 0; l < kPhotonGridLevels - 1; ++l) {
        int stride = 1 << (kPhotonGridLevels - 1 - l);
        if (t.x % stride == 0 && t.y % stride == 0) return l;
    }
    return kPhotonGridLevels - 1;
}
float photonLevelStride(int level) { return float(1 << (kPhotonGridLevels - 1 - level)); }
// The grid's counter (and first-index) slot of a bucket's level: a bucket's levels are adjacent,
// so that its photons sit at [first[slot(b, 0)], first[slot(b + 1, 0)]) ordered by level.
int photonSlot(int bucket, int level) { return bucket * kPhotonGridLevels + level; }

#ifdef MIRAGE_CAUSTIC_GATHER
// The photon gather (specular_light.frag's variant for frames with a photon grid): the caustic
// irradiance at a reflected / refracted ray's hit, which the camera-space caustic buffer cannot
// hold (the camera does not see that point).
layout(std430, binding = kBindingPhotonGrid) readonly buffer PhotonGridCells { uint photonGrid[]; };
layout(std430, binding = kBindingPhotons) readonly buffer PhotonRecords { GpuPhoton photons[]; };
uniform float photonCellSize;  // m: 2 x RendererOptions::causticGatherRadius
uniform uint photonGatherCap;  // photons read per bucket, 0: all (CausticOptions gather cap)

// A gather point's footprint (m): the spacing of the neighbouring pixels' hits on its surface,
// from the screen-space derivatives dx, dy of the hit position. Across a silhouette (another
// surface, a miss) a derivative says nothing: one longer than 4x what a straight path of
// `pathLength` m meeting the surface at cosine `cosHit` gives for one pixel (pathLength / (f cos))
// is replaced by that.
float gatherFootprint(vec3 dx, vec3 dy, float pathLength, float cosHit) {
    float f = abs(projMatrix[0][0]) * 0.5 * canvas.x;  // pixels per radian at the centre
    float straight = pathLength / (f * clamp(cosHit, 0.2, 1.0));
    float a = length(dx), b = length(dy);
    a = a > 4.0 * straight || !(a >= 0.0) ? straight : a;
    b = b > 4.0 * straight || !(b >= 0.0) ? straight : b;
    return max(a, b);
}

// Kernel density estimate of the caustic irradiance (W/m^2) at receiver point x with unit
// normal n (facing the ray that found x), for L_rv and for L_r: the sum over photons i of
// power_i K(|x - x_i|), K the 2D Epanechnikov kernel K(d) = 2 / (pi r^2) (1 - d^2 / r^2) (it
// integrates to 1 over the receiver's plane: each photon deposits its power, as in the splat) of
// radius r = min(max(r_i, 1.5 footprint), R), R = max(h / 2, min(1.5 footprint, h)): sampled at
// the pixels' hits, a kernel narrower than 1.5 pixel spacings would alias (a caustic focused onto
// one pixel centre would count up to 2x, or be missed), so where the pixels are coarser than the
// grid the gather reaches up to a whole cell (3x3x3 cells) instead of half a cell (2x2x2). Only
// photons on x's surface count: the photon's receiver normal within 60 degrees of n, and x
// within r / 2 of the photon's tangent plane. No photon in range: 0.
void gatherCaustic(vec3 x, vec3 n, float footprint, out vec3 eRv, out vec3 eR) {
    eRv = vec3(0.0);
    eR = vec3(0.0);
    float h = photonCellSize;
    float reach = max(0.5 * h, min(1.5 * footprint, h));
    ivec3 lo = ivec3(floor((x - reach) / h)), hi = ivec3(floor((x + reach) / h));
    int visited[27];
    int nVisited = 0;
    for (int cz = lo.z; cz <= hi.z; ++cz)
        for (int cy = lo.y; cy <= hi.y; ++cy)
            for (int cx = lo.x; cx <= hi.x; ++cx) {
                ivec3 cell = ivec3(cx, cy, cz);
                // A cell farther than the reach from x holds no photon whose kernel reaches x.
                vec3 c0 = vec3(cell) * h, nearest = clamp(x, c0, c0 + h);
                if (dot(x - nearest, x - nearest) > reach * reach) continue;
                int b = photonBucket(cell);
                bool seen = false;  // two cells hashed to one bucket: its list once
                for (int j = 0; j < nVisited; ++j) seen = seen || visited[j] == b;
                if (seen || nVisited >= 27) continue;
                visited[nVisited++] = b;
                // A bucket fuller than the cap is read by its finest prefix of levels (a
                // stratified subsample of the photon map: every 2nd, 4th, 8th or 16th texel per
                // axis) of at most cap photons; if that prefix is empty (the bucket's photons lie
                // off the coarse lattices), the coarsest non-empty one. Which photons are read
                // depends on their texels only, never on the order the scatter stored them in,
                // so a capped frame is reproducible. What is read stands for the whole bucket
                // (weight count / read), and each photon read for a stride x stride block of the
                // map, so its kernel widens by the stride (its spacing to its read neighbours).
                int s0 = photonSlot(b, 0);
                uint first = photonGrid[kPhotonGridSlots + s0];
                uint last = photonGrid[kPhotonGridSlots + s0 + kPhotonGridLevels];
                uint count = last - first, end = last;
                if (count == 0u) continue;
                float widen = 1.0;
                if (photonGatherCap > 0u && count > photonGatherCap) {
                    for (int l = kPhotonGridLevels - 2; l >= 0; --l) {
                        uint e = photonGrid[kPhotonGridSlots + s0 + l + 1];
                        if (e == first) break;  // this prefix and every coarser one empty
                        end = e;
                        widen = photonLevelStride(l);
                        if (e - first <= photonGatherCap) break;
                    }
                }
                float share = float(count) / float(end - first);
                vec3 bucketRv = vec3(0.0), bucketR = vec3(0.0);
                for (uint i = first; i < end; ++i) {
                    vec3 d = x - photons[i].position;
                    float r = min(max(widen * photons[i].radius, 1.5 * footprint), reach);
                    float d2 = dot(d, d), r2 = r * r;
                    if (d2 >= r2) continue;
                    vec3 np = unpackNormalOct(photons[i].normal);
                    if (dot(np, n) < 0.5 || abs(dot(d, np)) > 0.5 * r) continue;
                    float w = 2.0 / (PI * r2) * (1.0 - d2 / r2);
                    bucketRv += photons[i].powerRv * w;
                    bucketR += photons[i].powerR * w;
                }
                eRv += share * bucketRv;
                eR += share * bucketR;
            }
}
#endif

#endif
