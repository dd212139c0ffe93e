#include "render/translucency/ExitAlbedo.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "render/raytrace/Bsdf.h"
#include "render/raytrace/Sampling.h"
#include "render/translucency/VoxelNumberMap.h"

namespace mirage::translucency {
namespace {

constexpr int kMaxEvents = 100000;  // per walk; Russian roulette ends walks long before

struct Walker {
    const WalkGrid& g;
    bool valid(glm::ivec3 c) const {
        return glm::all(glm::greaterThanEqual(c, glm::ivec3(0))) &&
               glm::all(glm::lessThan(c, g.dims));
    }
    size_t index(glm::ivec3 c) const {
        return (size_t(c.z) * size_t(g.dims.y) + size_t(c.y)) * size_t(g.dims.x) + size_t(c.x);
    }
    bool inside(glm::ivec3 c) const { return valid(c) && (*g.inside)[index(c)] != 0; }

    // 3D DDA from p along unit d over (0, tMax]: the first cell whose `inside` differs from
    // `wantInside`, where the ray enters it (t) and the axis of the face it crosses. False if the
    // ray stays in such cells up to tMax (or leaves the grid: then cell is outside it).
    bool firstChange(glm::vec3 p, glm::vec3 d, float tMax, bool wantInside, float& t,
                     glm::ivec3& cell, int& axis) const {
        glm::ivec3 c = glm::ivec3(glm::floor(p));
        glm::ivec3 step;
        glm::vec3 tNext, tDelta;
        for (int k = 0; k < 3; ++k) {
            step[k] = d[k] > 0 ? 1 : -1;
            tDelta[k] = d[k] != 0 ? std::abs(1.0f / d[k]) : std::numeric_limits<float>::infinity();
            const float boundary = d[k] > 0 ? std::floor(p[k]) + 1.0f : std::floor(p[k]);
            tNext[k] =
                d[k] != 0 ? (boundary - p[k]) / d[k] : std::numeric_limits<float>::infinity();
        }
        for (int guard = 0; guard < 4 * (g.dims.x + g.dims.y + g.dims.z); ++guard) {
            const int k =
                tNext.x < tNext.y ? (tNext.x < tNext.z ? 0 : 2) : (tNext.y < tNext.z ? 1 : 2);
            if (tNext[k] > tMax) return false;
            c[k] += step[k];
            if (inside(c) != wantInside || !valid(c)) {
                t = tNext[k];
                cell = c;
                axis = k;
                return true;
            }
            tNext[k] += tDelta[k];
        }
        return false;
    }
};

}  // namespace

glm::vec3 measureExitAlbedo(const WalkGrid& grid, const std::vector<WalkStart>& starts,
                            const glm::vec3& albedo, float ior, int walks, uint64_t seed) {
    float majorant = 0.0f;
    for (size_t i = 0; i < grid.sigma->size(); ++i)
        if ((*grid.inside)[i]) majorant = std::max(majorant, (*grid.sigma)[i]);
    std::vector<double> cdf;
    double total = 0.0;
    for (const WalkStart& s : starts) cdf.push_back(total += std::max(0.0f, s.area));
    if (!(majorant > 0) || !(total > 0) || walks < 1) return effectiveAlbedo(albedo);
    const Walker w{grid};
    raytrace::Rng rng(seed, 0x7a1c);
    auto reflectance = [&](float cosAbs) {
        return ior == 1.0f ? 0.0f : raytrace::fresnelDielectric(std::min(1.0f, cosAbs), ior);
    };
    glm::dvec3 left(0.0);
    int scatteredWalks = 0;
    for (int n = 0; n < walks; ++n) {
        const double pick = double(rng.uniform()) * total;
        const size_t i = size_t(std::lower_bound(cdf.begin(), cdf.end(), pick) - cdf.begin());
        const WalkStart& s = starts[std::min(i, starts.size() - 1)];
        glm::vec3 p = glm::vec3(s.cell) + 0.5f;
        glm::vec3 d =
            raytrace::Frame(-s.normal).toWorld(raytrace::sampleCosineHemisphere(rng.uniform2()));
        glm::vec3 weight(1.0f);
        bool scattered = false;
        for (int event = 0; event < kMaxEvents; ++event) {
            const float t = -std::log(1.0f - rng.uniform()) / majorant;
            float tb;
            glm::ivec3 c;
            int axis;
            if (w.firstChange(p, d, t, true, tb, c, axis)) {
                // At the boundary (the face of cell c): Fresnel reflection, else out.
                const glm::vec3 q = p + d * tb;
                if (rng.uniform() < reflectance(std::abs(d[axis]))) {
                    d[axis] = -d[axis];
                    p = q + d * 1e-4f;
                    continue;
                }
                if (!w.valid(c) || (*grid.exterior)[w.index(c)]) {
                    if (scattered) left += glm::dvec3(weight);
                    break;
                }
                // A cavity: straight across to the medium on its far side.
                float tc;
                glm::ivec3 far;
                int farAxis;
                if (!w.firstChange(q + d * 1e-4f, d, 1e9f, false, tc, far, farAxis) ||
                    !w.inside(far))
                    break;  // open to the outside: leaves (cannot happen for a cavity)
                p = q + d * (tc + 2e-4f);
                continue;
            }
            p += d * t;
            const glm::ivec3 cell = glm::ivec3(glm::floor(p));
            if (!w.inside(cell)) continue;  // numerically on a face: a null collision
            if (rng.uniform() * majorant >= (*grid.sigma)[w.index(cell)]) continue;  // null
            weight *= albedo;
            scattered = true;
            d = raytrace::sampleUniformSphere(rng.uniform2());
            const float m = std::max(weight.x, std::max(weight.y, weight.z));
            if (m < 0.05f) {  // Russian roulette: unbiased
                if (rng.uniform() < 0.5f) break;
                weight *= 2.0f;
            }
        }
        scatteredWalks += scattered ? 1 : 0;
    }
    if (scatteredWalks == 0) return effectiveAlbedo(albedo);
    return glm::vec3(left / double(scatteredWalks));
}

}  // namespace mirage::translucency
