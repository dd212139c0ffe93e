// Helpers shared by the caustic passes (include after common.glsl): the photon G-buffers' texel
// decoding and the photons' footprint (caustic_splat.comp, photon_grid_*.comp), the routing of a
// caustic's irradiance into the two GI solutions (caustic_resolve.frag for the camera's pixels,
// the photon gather of specular_light.frag for the reflected / refracted hits), and the hashed
// cell of the world-space photon grid. World metres, linear W and W/m^2.
#ifndef MIRAGE_CAUSTIC_GLSL
#define MIRAGE_CAUSTIC_GLSL

// Photon hit texel: xyz world receiver hit, w = 4 x hit origin + real-path visibility.
int photonHitOrigin(vec4 hit) { return int(floor((hit.w + 0.5) / 4.0)); }

// A photon texel's powers for L_rv (power x visibility through all occluders) and for L_r (power
// x real-path visibility: nonzero only when the light and the specular object are real). False
// when there is no photon (no specular surface at the texel, or it left the modelled scene) or
// it carries nothing.
bool photonPowers(vec4 hit, vec4 power, out vec3 powerRv, out vec3 powerR) {
    powerRv = vec3(0.0);
    powerR = vec3(0.0);
    int origin = photonHitOrigin(hit);
    if (origin == ORIGIN_NONE) return false;
    float realVis = hit.w - 4.0 * float(origin);
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

#ifdef MIRAGE_CAUSTIC_GATHER
// The photon gather (specular_light.frag's variant for frames with a photon grid): the caustic
// irradiance at a reflected / refracted ray's hit, which the camera-space caustic buffer cannot
// hold (the camera does not see that point).
layout(std430, binding = kBindingPhotonGrid) readonly buffer PhotonGridCells { uint photonGrid[]; };
layout(std430, binding = kBindingPhotons) readonly buffer PhotonRecords { GpuPhoton photons[]; };
uniform float photonCellSize;  // m: 2 x RendererOptions::causticGatherRadius
uniform uint photonGatherCap;  // photons read per bucket, 0: all (RendererOptions::causticGatherCap)

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
                uint first = photonGrid[kPhotonGridCells + b];
                uint last = photonGrid[kPhotonGridCells + b + 1];
                // A bucket fuller than the cap is read with a stride from an offset that varies
                // by pixel and bucket (not by frame: a frame depends on its inputs only, so a
                // frame after a history reset equals a fresh renderer's); what is read stands
                // for the whole bucket (weight count / read). The scatter fills a bucket roughly
                // in photon-map order, so a stride samples the bucket's whole footprint of the
                // map rather than one corner of it.
                uint count = last - first, stride = 1u;
                if (count == 0u) continue;
                if (photonGatherCap > 0u && count > photonGatherCap)
                    stride = (count + photonGatherCap - 1u) / photonGatherCap;
                uint start = first;
                if (stride > 1u) {
                    uvec2 p = uvec2(gl_FragCoord.xy);
                    uint seed = (p.x * 73856093u) ^ (p.y * 19349663u) ^ uint(b);
                    seed = (seed ^ (seed >> 16)) * 0x45d9f3bu;
                    start += (seed ^ (seed >> 16)) % stride;
                }
                float share = float(count) / float((last - start + stride - 1u) / stride);
                vec3 bucketRv = vec3(0.0), bucketR = vec3(0.0);
                for (uint i = start; i < last; i += stride) {
                    vec3 d = x - photons[i].position;
                    float r = min(max(photons[i].radius, 1.5 * footprint), reach);
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
