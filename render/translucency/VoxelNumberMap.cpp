#include "render/translucency/VoxelNumberMap.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <thread>

#include <glm/gtc/packing.hpp>

#include "core/Error.h"
#include "core/Log.h"
#include "core/ParallelFor.h"
#include "render/raytrace/Bsdf.h"
#include "render/raytrace/Sampling.h"
#include "render/translucency/ExitAlbedo.h"

namespace mirage::translucency {
namespace {

namespace fs = std::filesystem;
using raytrace::kPi;

constexpr uint32_t kCacheMagic = 0x314D4E56;  // "VNM1"
constexpr uint32_t kCacheVersion = 3;

int threadCount(int requested) {
    return requested > 0 ? requested : int(std::max(1u, std::thread::hardware_concurrency()));
}

// FNV-1a over bytes.
struct Hasher {
    uint64_t h = 1469598103934665603ull;
    void bytes(const void* p, size_t n) {
        auto* c = static_cast<const unsigned char*>(p);
        for (size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ull;
    }
    template <typename T>
    void value(const T& v) {
        bytes(&v, sizeof(T));
    }
};

}  // namespace

float boundaryTransmittance(float ior, float cosAbs) {
    return ior == 1.0f ? 1.0f
                       : 1.0f - raytrace::fresnelDielectric(std::clamp(cosAbs, 0.0f, 1.0f), ior);
}

float hemisphericalTransmittance(float ior) {
    // Midpoint rule in mu; F_t is smooth, 256 steps are exact to ~1e-5.
    constexpr int kSteps = 256;
    double sum = 0.0;
    for (int k = 0; k < kSteps; ++k) {
        const float mu = (float(k) + 0.5f) / float(kSteps);
        sum += double(boundaryTransmittance(ior, mu)) * mu;
    }
    return float(2.0 * sum / kSteps);
}

glm::vec3 effectiveAlbedo(const glm::vec3& albedo) {
    glm::vec3 out;
    for (int k = 0; k < 3; ++k) {
        const float g = std::sqrt(std::max(0.0f, 1.0f - std::clamp(albedo[k], 0.0f, 1.0f)));
        out[k] = (1.0f - g) / (1.0f + g);
    }
    return out;
}

glm::vec3 kernelFalloff(const glm::vec3& albedo, VnmKernel kernel) {
    if (kernel == VnmKernel::Extinction) return glm::vec3(1.0f);
    glm::vec3 k;
    for (int c = 0; c < 3; ++c)
        k[c] = std::min(1.0f, std::sqrt(3.0f * (1.0f - std::clamp(albedo[c], 0.0f, 1.0f))));
    return k;
}

glm::vec3 shadowExtinctionScale(const glm::vec3& albedo) {
    // The light removed from the shadow ray over tau, e^{-tau} aside, is scattered; a_eff of it
    // leaves the object (effectiveAlbedo), about half of that on the side away from the light,
    // and a receiver near that side sees it over about half its hemisphere: a quarter of
    // a_eff (1 - e^{-tau}) arrives, which e^{-(1 - a_eff / 4) tau} follows to within a few per
    // cent for tau up to ~2 (docs/translucency.md "Shadows").
    return glm::vec3(1.0f) - 0.25f * effectiveAlbedo(albedo);
}

std::vector<TranslucentObject> translucentObjects(const Scene& scene) {
    std::vector<TranslucentObject> out;
    for (const MeshInstance& mi : scene.meshInstances()) {
        if (mi.mesh < 0 || mi.mesh >= int(scene.meshes.size())) continue;
        const Mesh& mesh = scene.meshes[size_t(mi.mesh)];
        std::vector<int> materials;
        for (const Primitive& p : mesh.primitives)
            if (scene.material(p.material).isTranslucent() &&
                std::find(materials.begin(), materials.end(), p.material) == materials.end())
                materials.push_back(p.material);
        for (int mat : materials) {
            const Material& m = scene.material(mat);
            TranslucentObject o;
            o.name = scene.nodes[size_t(mi.node)].name;
            o.medium.extinction = m.scattering.extinction;
            o.medium.albedo = m.scattering.albedo;
            o.medium.density = m.scattering.density;
            o.medium.localFromWorld = glm::mat4(glm::inverse(mi.world));
            o.medium.ior = m.ior;
            o.medium.majorant = m.scattering.extinction *
                                (m.scattering.density ? m.scattering.density->maxValue : 1);
            for (const Primitive& p : mesh.primitives) {
                if (p.material != mat) continue;
                auto base = uint32_t(o.positions.size());
                for (const glm::vec3& v : p.positions)
                    o.positions.push_back(glm::vec3(mi.world * glm::dvec4(v, 1.0)));
                for (uint32_t i : p.indices) o.indices.push_back(base + i);
            }
            out.push_back(std::move(o));
        }
    }
    return out;
}

std::string VoxelNumberMap::cacheKey(const TranslucentObject& o, const VnmSettings& s) {
    Hasher h;
    h.value(kCacheVersion);
    h.value(s.resolution);
    h.value(s.surface);
    h.value(kernelFalloff(o.medium.albedo, s.kernel));
    h.value(o.medium.albedo);
    h.value(o.medium.ior);
    h.value(s.albedoWalks);
    h.bytes(o.positions.data(), o.positions.size() * sizeof(glm::vec3));
    h.bytes(o.indices.data(), o.indices.size() * sizeof(uint32_t));
    h.value(o.medium.extinction);
    h.value(o.medium.localFromWorld);
    if (o.medium.density) {
        const DensityGrid& g = *o.medium.density;
        h.value(g.nx);
        h.value(g.ny);
        h.value(g.nz);
        h.value(g.boundsMin);
        h.value(g.boundsMax);
        h.bytes(g.values.data(), g.values.size() * sizeof(float));
    }
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h.h));
    return buf;
}

float VoxelNumberMap::tau(int i, int j) const {
    return glm::unpackHalf1x16(tau_[size_t(i) * surface_.size() + size_t(j)]);
}

int VoxelNumberMap::surfaceVoxelAt(const glm::vec3& p) const {
    glm::ivec3 c = glm::ivec3(glm::floor((p - origin_) / voxelSize_));
    auto valid = [&](glm::ivec3 q) {
        return glm::all(glm::greaterThanEqual(q, glm::ivec3(0))) &&
               glm::all(glm::lessThan(q, dims_));
    };
    if (valid(c) && number_[size_t(cellIndex(c))] >= 0) return number_[size_t(cellIndex(c))];
    int best = -1;
    float bestD = std::numeric_limits<float>::max();
    for (int dz = -2; dz <= 2; ++dz)
        for (int dy = -2; dy <= 2; ++dy)
            for (int dx = -2; dx <= 2; ++dx) {
                glm::ivec3 q = c + glm::ivec3(dx, dy, dz);
                if (!valid(q)) continue;
                int n = number_[size_t(cellIndex(q))];
                if (n < 0) continue;
                float d = glm::length(surface_[size_t(n)].position - p);
                if (d < bestD) {
                    bestD = d;
                    best = n;
                }
            }
    return best;
}

float VoxelNumberMap::filterWeight(float d) {
    const float x = d / kFilterRadius;
    return x < 1.0f ? (1.0f - x * x) * (1.0f - x * x) : 0.0f;
}

std::vector<VoxelWeight> VoxelNumberMap::reconstructionAt(const glm::vec3& p) const {
    // Every centre within kFilterRadius (1.5) voxels of a point in cell c lies in c's 3x3x3.
    const glm::vec3 g = (p - origin_) / voxelSize_;
    const glm::ivec3 c = glm::ivec3(glm::floor(g));
    std::vector<VoxelWeight> out;
    float sum = 0.0f;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const glm::ivec3 q = c + glm::ivec3(dx, dy, dz);
                if (glm::any(glm::lessThan(q, glm::ivec3(0))) ||
                    glm::any(glm::greaterThanEqual(q, dims_)))
                    continue;
                const int n = number_[size_t(cellIndex(q))];
                if (n < 0) continue;
                const float w = filterWeight(glm::length(glm::vec3(q) + 0.5f - g));
                if (w <= 0.0f) continue;
                out.push_back({n, w});
                sum += w;
            }
    if (sum > 0.0f) {
        for (VoxelWeight& v : out) v.weight /= sum;
        return out;
    }
    const int nearest = surfaceVoxelAt(p);
    if (nearest >= 0) return {{nearest, 1.0f}};
    return {};
}

// Cubic voxels over the bounding box with one empty voxel of margin (sets the grid); returns
// 1 per voxel whose centre is inside the mesh.
std::vector<uint8_t> VoxelNumberMap::voxelise(const TranslucentObject& o, int resolution) {
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (const auto& p : o.positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    const glm::vec3 extent = hi - lo;
    const float longest = std::max(extent.x, std::max(extent.y, extent.z));
    if (!(longest > 0) || !std::isfinite(longest))
        throw Error("voxel number map: translucent object '" + o.name + "' has no extent");
    voxelSize_ = longest / float(resolution);
    const float h = voxelSize_;
    dims_ = glm::ivec3(glm::ceil(extent / h - 1e-4f)) + 2;
    dims_ = glm::max(dims_, glm::ivec3(3));
    origin_ = lo - glm::vec3(h);
    const glm::ivec3 n = dims_;
    const size_t cells = size_t(n.x) * size_t(n.y) * size_t(n.z);
    std::vector<uint8_t> inside(cells, 0);
    // Inside test by parity along +x rows through the voxel centres (rows nudged off the voxel
    // lattice so that they do not run through mesh edges of axis-aligned meshes).
    const float nudgeY = 1.234567e-3f * h, nudgeZ = 2.345678e-3f * h;
    std::vector<std::vector<float>> crossings(size_t(n.y) * size_t(n.z));
    for (size_t t = 0; t + 2 < o.indices.size(); t += 3) {
        const glm::vec3 a = o.positions[o.indices[t]], b = o.positions[o.indices[t + 1]],
                        c = o.positions[o.indices[t + 2]];
        const glm::vec3 tlo = glm::min(a, glm::min(b, c)), thi = glm::max(a, glm::max(b, c));
        int y0 = std::max(0, int(std::floor((tlo.y - origin_.y) / h - 0.5f)));
        int y1 = std::min(n.y - 1, int(std::ceil((thi.y - origin_.y) / h - 0.5f)));
        int z0 = std::max(0, int(std::floor((tlo.z - origin_.z) / h - 0.5f)));
        int z1 = std::min(n.z - 1, int(std::ceil((thi.z - origin_.z) / h - 0.5f)));
        for (int z = z0; z <= z1; ++z)
            for (int y = y0; y <= y1; ++y) {
                const float py = origin_.y + (float(y) + 0.5f) * h + nudgeY;
                const float pz = origin_.z + (float(z) + 0.5f) * h + nudgeZ;
                // Barycentric test in the yz projection.
                const float d = (b.y - a.y) * (c.z - a.z) - (c.y - a.y) * (b.z - a.z);
                if (std::abs(d) < 1e-20f) continue;
                const float u = ((py - a.y) * (c.z - a.z) - (c.y - a.y) * (pz - a.z)) / d;
                const float v = ((b.y - a.y) * (pz - a.z) - (py - a.y) * (b.z - a.z)) / d;
                if (u < 0 || v < 0 || u + v > 1) continue;
                crossings[size_t(z) * size_t(n.y) + size_t(y)].push_back(a.x + u * (b.x - a.x) +
                                                                         v * (c.x - a.x));
            }
    }
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y) {
            auto& xs = crossings[size_t(z) * size_t(n.y) + size_t(y)];
            std::sort(xs.begin(), xs.end());
            for (size_t k = 0; k + 1 < xs.size(); k += 2)
                for (int x = 0; x < n.x; ++x) {
                    float px = origin_.x + (float(x) + 0.5f) * h;
                    if (px >= xs[k] && px < xs[k + 1]) inside[size_t(cellIndex({x, y, z}))] = 1;
                }
        }

    return inside;
}

// Extinction per voxel: the mean of 8 sub-samples of sigma_t inside, 0 outside.
std::vector<float> VoxelNumberMap::extinction(const TranslucentObject& o,
                                              const std::vector<uint8_t>& inside) const {
    const float h = voxelSize_;
    const glm::ivec3 n = dims_;
    std::vector<float> sigma(inside.size(), 0.0f);
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                size_t idx = size_t(cellIndex({x, y, z}));
                if (!inside[idx]) continue;
                float sum = 0.0f;
                for (int k = 0; k < 8; ++k) {
                    glm::vec3 sub(k & 1 ? 0.75f : 0.25f, k & 2 ? 0.75f : 0.25f,
                                  k & 4 ? 0.75f : 0.25f);
                    sum += o.medium.sigmaT(origin_ + (glm::vec3(x, y, z) + sub) * h);
                }
                sigma[idx] = sum / 8.0f;
            }

    return sigma;
}

// The exterior: empty voxels reached from the grid's border (the other empty ones are cavities).
std::vector<uint8_t> VoxelNumberMap::exteriorOf(const std::vector<uint8_t>& inside) const {
    const glm::ivec3 n = dims_;
    std::vector<uint8_t> exterior(inside.size(), 0);
    {
        std::vector<glm::ivec3> stack;
        for (int z = 0; z < n.z; ++z)
            for (int y = 0; y < n.y; ++y)
                for (int x = 0; x < n.x; ++x)
                    if (x == 0 || y == 0 || z == 0 || x == n.x - 1 || y == n.y - 1 || z == n.z - 1)
                        stack.push_back({x, y, z});
        while (!stack.empty()) {
            glm::ivec3 c = stack.back();
            stack.pop_back();
            if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c, n)))
                continue;
            size_t idx = size_t(cellIndex(c));
            if (inside[idx] || exterior[idx]) continue;
            exterior[idx] = 1;
            for (int axis = 0; axis < 3; ++axis)
                for (int sgn : {-1, 1}) {
                    glm::ivec3 q = c;
                    q[axis] += sgn;
                    stack.push_back(q);
                }
        }
    }

    return exterior;
}

// Surface voxels: inside with an outside 6-neighbour, normals from 26 neighbours, areas the
// mesh's area shared in proportion to each voxel's exposed faces.
void VoxelNumberMap::findSurface(const TranslucentObject& o, const VnmSettings& s,
                                 const std::vector<uint8_t>& inside,
                                 const std::vector<uint8_t>& exterior) {
    const float h = voxelSize_;
    const glm::ivec3 n = dims_;
    number_.assign(inside.size(), -1);
    int exposedTotal = 0;
    std::vector<int> exposed;
    auto isInside = [&](glm::ivec3 q) {
        if (glm::any(glm::lessThan(q, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(q, n)))
            return false;
        return inside[size_t(cellIndex(q))] != 0;
    };
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                glm::ivec3 c(x, y, z);
                if (!isInside(c)) continue;
                int faces = 0;
                bool outer = false;
                for (int axis = 0; axis < 3; ++axis)
                    for (int sgn : {-1, 1}) {
                        glm::ivec3 q = c;
                        q[axis] += sgn;
                        if (isInside(q)) continue;
                        ++faces;
                        outer = outer || exterior[size_t(cellIndex(q))];
                    }
                if (!faces) continue;
                glm::vec3 normal(0.0f);
                for (int dz = -1; dz <= 1; ++dz)
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dx = -1; dx <= 1; ++dx) {
                            glm::ivec3 q = c + glm::ivec3(dx, dy, dz);
                            if ((dx || dy || dz) && !isInside(q))
                                normal += glm::normalize(glm::vec3(dx, dy, dz));
                        }
                SurfaceVoxel sv;
                sv.cell = c;
                sv.exterior = outer ? 1 : 0;
                sv.position = origin_ + (glm::vec3(c) + 0.5f) * h;
                sv.normal = glm::length(normal) > 0 ? glm::normalize(normal) : glm::vec3(0, 1, 0);
                number_[size_t(cellIndex(c))] = int32_t(surface_.size());
                surface_.push_back(sv);
                exposed.push_back(faces);
                exposedTotal += faces;
            }
    const size_t S = surface_.size();
    if (S == 0)
        throw Error("voxel number map: translucent object '" + o.name +
                    "' has no inside voxel at "
                    "resolution " +
                    std::to_string(s.resolution) +
                    " (an open or too thin mesh); close the mesh or raise the resolution");
    const size_t bytes = lutBytes(S);
    if (bytes > s.maxLutBytes)
        throw Error("voxel number map: object '" + o.name + "' at resolution " +
                    std::to_string(s.resolution) + " has " + std::to_string(S) +
                    " surface voxels; its optical-thickness LUT would need " +
                    std::to_string(bytes >> 20) + " MiB (S^2 x 2 bytes), more than the limit of " +
                    std::to_string(s.maxLutBytes >> 20) + " MiB; lower the voxel resolution");
    // Areas: the mesh's area shared in proportion to each voxel's exposed faces.
    double area = 0.0;
    for (size_t t = 0; t + 2 < o.indices.size(); t += 3)
        area += 0.5 * double(glm::length(
                          glm::cross(o.positions[o.indices[t + 1]] - o.positions[o.indices[t]],
                                     o.positions[o.indices[t + 2]] - o.positions[o.indices[t]])));
    for (size_t i = 0; i < S; ++i) surface_[i].area = float(area * exposed[i] / exposedTotal);
    // The outer surface's area: light leaves the object only there (a cavity wall passes what
    // reaches it on through the cavity, which the LUT's optical thickness already skips).
    area_ = 0.0f;
    for (const SurfaceVoxel& v : surface_) area_ += v.exterior ? v.area : 0.0f;
}

// Normals and areas from the mesh: each triangle cut into m^2 equal parts (edges of at most a
// quarter voxel), each part's area and normal given to the surface voxel standing for its centre
// (surfaceVoxelAt). A voxel that gets no part keeps its occupancy normal and stands for no area.
// The triangle's normal is turned to agree with the occupancy normal (outward from the medium,
// into a cavity on its walls), so the winding of the mesh does not matter.
void VoxelNumberMap::meshSurface(const TranslucentObject& o) {
    const size_t S = surface_.size();
    std::vector<double> area(S, 0.0);
    std::vector<glm::dvec3> normal(S, glm::dvec3(0.0));
    const float step = 0.25f * voxelSize_;
    for (size_t t = 0; t + 2 < o.indices.size(); t += 3) {
        const glm::vec3 a = o.positions[o.indices[t]], b = o.positions[o.indices[t + 1]],
                        c = o.positions[o.indices[t + 2]];
        const glm::vec3 cr = glm::cross(b - a, c - a);
        const float len = glm::length(cr);
        if (!(len > 0.0f) || !std::isfinite(len)) continue;
        const glm::vec3 n = cr / len;
        const float longest =
            std::max(glm::length(b - a), std::max(glm::length(c - a), glm::length(c - b)));
        const int m = std::clamp(int(std::ceil(longest / step)), 1, 4096);
        const double part = 0.5 * double(len) / double(m) / double(m);
        auto add = [&](float u, float v) {
            const glm::vec3 p = a + (u / float(m)) * (b - a) + (v / float(m)) * (c - a);
            const int i = surfaceVoxelAt(p);
            if (i < 0) return;
            const float sgn = glm::dot(n, surface_[size_t(i)].normal) < 0.0f ? -1.0f : 1.0f;
            area[size_t(i)] += part;
            normal[size_t(i)] += part * glm::dvec3(sgn * n);
        };
        for (int i = 0; i < m; ++i)
            for (int j = 0; i + j < m; ++j) {
                add(float(i) + 1.0f / 3.0f, float(j) + 1.0f / 3.0f);
                if (i + j + 2 <= m) add(float(i) + 2.0f / 3.0f, float(j) + 2.0f / 3.0f);
            }
    }
    for (size_t i = 0; i < S; ++i) {
        surface_[i].area = float(area[i]);
        if (glm::length(normal[i]) > 0.0) surface_[i].normal = glm::vec3(glm::normalize(normal[i]));
    }
    area_ = 0.0f;
    for (const SurfaceVoxel& v : surface_) area_ += v.exterior ? v.area : 0.0f;
}

// Optical thickness between every pair of surface voxels (3D DDA through the voxel
// extinctions).
void VoxelNumberMap::opticalThickness(const std::vector<float>& sigma, int threads) {
    const float h = voxelSize_;
    const glm::ivec3 n = dims_;
    const size_t S = surface_.size();
    tau_.assign(S * S, 0);
    auto march = [&](glm::vec3 a, glm::vec3 b) {
        // Voxel-space coordinates.
        glm::vec3 pa = (a - origin_) / h, pb = (b - origin_) / h;
        glm::vec3 d = pb - pa;
        float len = glm::length(d);
        if (len <= 0) return 0.0f;
        glm::ivec3 c = glm::ivec3(glm::floor(pa));
        const glm::ivec3 last = glm::ivec3(glm::floor(pb));
        glm::ivec3 step;
        glm::vec3 tMax, tDelta;
        for (int k = 0; k < 3; ++k) {
            step[k] = d[k] > 0 ? 1 : (d[k] < 0 ? -1 : 0);
            if (step[k] == 0) {
                tMax[k] = std::numeric_limits<float>::infinity();
                tDelta[k] = std::numeric_limits<float>::infinity();
            } else {
                float boundary = step[k] > 0 ? std::floor(pa[k]) + 1.0f : std::floor(pa[k]);
                tMax[k] = (boundary - pa[k]) / d[k];
                tDelta[k] = float(step[k]) / d[k];
            }
        }
        float t = 0.0f, tau = 0.0f;
        for (int guard = 0; guard < 4 * (n.x + n.y + n.z); ++guard) {
            int k = tMax.x < tMax.y ? (tMax.x < tMax.z ? 0 : 2) : (tMax.y < tMax.z ? 1 : 2);
            float tNext = std::min(tMax[k], 1.0f);
            if (glm::all(glm::greaterThanEqual(c, glm::ivec3(0))) && glm::all(glm::lessThan(c, n)))
                tau += sigma[size_t(cellIndex(c))] * (tNext - t);
            if (tNext >= 1.0f || c == last) break;
            t = tNext;
            c[k] += step[k];
            tMax[k] += tDelta[k];
        }
        return tau * len * h;
    };
    parallelFor(int(S), threadCount(threads), [&](int i) {
        for (size_t j = size_t(i) + 1; j < S; ++j) {
            uint16_t v = glm::packHalf1x16(
                std::min(65000.0f, march(surface_[size_t(i)].position, surface_[j].position)));
            tau_[size_t(i) * S + j] = v;
            tau_[j * S + size_t(i)] = v;
        }
    });
}

// The kernel scales c_i = (1 - T_i) / W_i per channel (VoxelNumberMap.h): what enters at i and
// does not pass straight through leaves the outer surface in total, spread as e^{-k tau}.
void VoxelNumberMap::kernelScales(const glm::vec3& k, int threads) {
    falloff_ = k;
    const size_t S = surface_.size();
    parallelFor(int(S), threadCount(threads), [&](int i) {
        glm::dvec3 W(0.0);
        double straight = 0.0;
        for (size_t j = 0; j < S; ++j) {
            if (!surface_[j].exterior) continue;
            const double t = double(tau(i, int(j))), A = surface_[j].area;
            straight += A * std::exp(-t);
            W += A * glm::dvec3(std::exp(-k.x * t), std::exp(-k.y * t), std::exp(-k.z * t));
        }
        const double scattered = area_ > 0 ? std::max(0.0, 1.0 - straight / double(area_)) : 0.0;
        glm::vec3 c(0.0f);
        for (int ch = 0; ch < 3; ++ch) c[ch] = W[ch] > 0 ? float(scattered / W[ch]) : 0.0f;
        surface_[size_t(i)].kernelScale = c;
    });
    // Near-field densities D_o = sum over outer voxels i within kNearField of o of
    // A_i e^{-k tau(i, o)} (green channel's k): on a flat face they should all be equal, but on
    // a face the grid cuts at an angle the voxel centres step in and out of it and the areas
    // step with them, so D_o (and with it the light leaving o) rises and falls in stripes.
    // g_o = mean D / D_o takes that out (a normalised convolution of the near field).
    const float reach = kNearField * voxelSize_;
    std::vector<double> density(S, 0.0);
    parallelFor(int(S), threadCount(threads), [&](int o) {
        double D = 0.0;
        for (size_t i = 0; i < S; ++i)
            if (surface_[i].exterior &&
                glm::length(surface_[i].position - surface_[size_t(o)].position) <= reach)
                D += surface_[i].area * std::exp(-double(k.y) * double(tau(int(i), o)));
        density[size_t(o)] = D;
    });
    double sum = 0.0, weight = 0.0;
    for (size_t o = 0; o < S; ++o)
        if (surface_[o].exterior && density[o] > 0) {
            sum += surface_[o].area * density[o];
            weight += surface_[o].area;
        }
    const double mean = weight > 0 ? sum / weight : 0.0;
    for (size_t o = 0; o < S; ++o)
        surface_[o].nearScale =
            density[o] > 0 && mean > 0 ? float(std::clamp(mean / density[o], 0.25, 4.0)) : 1.0f;
}

VoxelNumberMap VoxelNumberMap::build(const TranslucentObject& o, const VnmSettings& s) {
    if (s.resolution < 2 || s.resolution > 512)
        throw Error("voxel number map: resolution " + std::to_string(s.resolution) +
                    " is outside 2..512");
    if (o.indices.size() < 3 || o.indices.size() % 3)
        throw Error("voxel number map: translucent object '" + o.name + "' has no triangles");
    const auto start = std::chrono::steady_clock::now();
    VoxelNumberMap m;
    const std::string key = cacheKey(o, s);
    const fs::path cacheFile =
        s.cacheDir.empty() ? fs::path() : s.cacheDir / ("vnm-" + key + ".bin");
    if (!cacheFile.empty() && m.readCache(cacheFile)) {
        m.fromCache_ = true;
        m.seconds_ =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return m;
    }

    const std::vector<uint8_t> inside = m.voxelise(o, s.resolution);
    const std::vector<uint8_t> exterior = m.exteriorOf(inside);
    m.findSurface(o, s, inside, exterior);
    if (s.surface == VnmSurface::Mesh) m.meshSurface(o);
    const std::vector<float> sigma = m.extinction(o, inside);
    m.opticalThickness(sigma, s.threads);
    m.kernelScales(kernelFalloff(o.medium.albedo, s.kernel), s.threads);
    // Random walks in voxel units: extinction per voxel edge.
    std::vector<float> sigmaPerVoxel(sigma.size());
    for (size_t i = 0; i < sigma.size(); ++i) sigmaPerVoxel[i] = sigma[i] * m.voxelSize_;
    std::vector<WalkStart> starts;
    for (const SurfaceVoxel& v : m.surface_)
        if (v.exterior) starts.push_back({v.cell, v.normal, v.area});
    m.exitAlbedo_ = measureExitAlbedo({m.dims_, &inside, &exterior, &sigmaPerVoxel}, starts,
                                      o.medium.albedo, o.medium.ior, s.albedoWalks);
    m.seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!cacheFile.empty()) m.writeCache(cacheFile);
    return m;
}

bool VoxelNumberMap::readCache(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) return false;
    uint32_t magic = 0, version = 0;
    uint64_t S = 0;
    in.read(reinterpret_cast<char*>(&magic), 4);
    in.read(reinterpret_cast<char*>(&version), 4);
    in.read(reinterpret_cast<char*>(&dims_), sizeof dims_);
    in.read(reinterpret_cast<char*>(&origin_), sizeof origin_);
    in.read(reinterpret_cast<char*>(&voxelSize_), sizeof voxelSize_);
    in.read(reinterpret_cast<char*>(&area_), sizeof area_);
    in.read(reinterpret_cast<char*>(&falloff_), sizeof falloff_);
    in.read(reinterpret_cast<char*>(&exitAlbedo_), sizeof exitAlbedo_);
    in.read(reinterpret_cast<char*>(&S), sizeof S);
    if (!in || magic != kCacheMagic || version != kCacheVersion ||
        glm::any(glm::lessThan(dims_, glm::ivec3(1))) ||
        glm::any(glm::greaterThan(dims_, glm::ivec3(1024))) || S == 0 || S > (uint64_t(1) << 20)) {
        spdlog::warn("voxel number map cache {} is damaged or of another version; recomputing",
                     file.string());
        return false;
    }
    // Allocate only what the file holds: a damaged header must not ask for a huge LUT.
    const uint64_t cells = uint64_t(dims_.x) * uint64_t(dims_.y) * uint64_t(dims_.z);
    const uint64_t expected =
        uint64_t(in.tellg()) + cells * 4 + S * sizeof(SurfaceVoxel) + S * S * 2;
    std::error_code ec;
    if (fs::file_size(file, ec) != expected || ec) {
        spdlog::warn(
            "voxel number map cache {} does not have the size its header states; "
            "recomputing",
            file.string());
        return false;
    }
    number_.resize(size_t(cells));
    surface_.resize(S);
    tau_.resize(S * S);
    in.read(reinterpret_cast<char*>(number_.data()), std::streamsize(number_.size() * 4));
    in.read(reinterpret_cast<char*>(surface_.data()), std::streamsize(S * sizeof(SurfaceVoxel)));
    in.read(reinterpret_cast<char*>(tau_.data()), std::streamsize(tau_.size() * 2));
    bool ok = bool(in);
    for (int32_t v : number_) ok = ok && v >= -1 && v < int32_t(S);
    if (!ok) {
        spdlog::warn("voxel number map cache {} is truncated or damaged; recomputing",
                     file.string());
        number_.clear();
        surface_.clear();
        tau_.clear();
        return false;
    }
    return true;
}

void VoxelNumberMap::writeCache(const fs::path& file) const {
    std::error_code ec;
    fs::create_directories(file.parent_path(), ec);
    const fs::path temp = file.string() + ".tmp";
    {
        std::ofstream out(temp, std::ios::binary);
        const uint64_t S = surface_.size();
        out.write(reinterpret_cast<const char*>(&kCacheMagic), 4);
        out.write(reinterpret_cast<const char*>(&kCacheVersion), 4);
        out.write(reinterpret_cast<const char*>(&dims_), sizeof dims_);
        out.write(reinterpret_cast<const char*>(&origin_), sizeof origin_);
        out.write(reinterpret_cast<const char*>(&voxelSize_), sizeof voxelSize_);
        out.write(reinterpret_cast<const char*>(&area_), sizeof area_);
        out.write(reinterpret_cast<const char*>(&falloff_), sizeof falloff_);
        out.write(reinterpret_cast<const char*>(&exitAlbedo_), sizeof exitAlbedo_);
        out.write(reinterpret_cast<const char*>(&S), sizeof S);
        out.write(reinterpret_cast<const char*>(number_.data()),
                  std::streamsize(number_.size() * 4));
        out.write(reinterpret_cast<const char*>(surface_.data()),
                  std::streamsize(S * sizeof(SurfaceVoxel)));
        out.write(reinterpret_cast<const char*>(tau_.data()), std::streamsize(tau_.size() * 2));
        if (!out) {
            spdlog::warn("could not write the voxel number map cache {}", file.string());
            fs::remove(temp, ec);
            return;
        }
    }
    fs::rename(temp, file, ec);
    if (ec)
        spdlog::warn("could not write the voxel number map cache {}: {}", file.string(),
                     ec.message());
}

// ---- run time -----------------------------------------------------------------------------------

glm::vec3 VnmShading::radianceScale(const VoxelNumberMap& map, const raytrace::Medium& medium,
                                    bool measured) {
    if (!measured) return effectiveAlbedo(medium.albedo) / kPi;
    return map.exitAlbedo() / (kPi * hemisphericalTransmittance(medium.ior));
}

VnmShading::VnmShading(const VoxelNumberMap& map, const TranslucentObject& object,
                       const raytrace::RayTracingScene& scene, int envSamples, bool measuredAlbedo)
    : map_(map), medium_(object.medium), scale_(radianceScale(map, object.medium, measuredAlbedo)) {
    const auto& sv = map.surface();
    E_.assign(sv.size(), glm::vec3(0.0f));
    const float offset = map.voxelSize();
    const float ior = medium_.ior;
    for (size_t i = 0; i < sv.size(); ++i) {
        const glm::vec3 N = sv[i].normal;
        // Visibility is tested from just outside the voxel, along its normal.
        const glm::vec3 x = sv[i].position + N * offset;
        glm::vec3 E(0.0f);
        for (const raytrace::PunctualLight& l : scene.lights()) {
            glm::vec3 wi, Li;
            float dist;
            if (l.type == Light::Type::Directional) {
                wi = -l.direction;
                dist = std::numeric_limits<float>::infinity();
                Li = l.intensity;
            } else {
                glm::vec3 v = l.position - sv[i].position;
                float d2 = glm::dot(v, v);
                if (!(d2 > 0)) continue;
                dist = std::sqrt(d2);
                wi = v / dist;
                Li = l.intensity * (l.spotFactor(glm::dot(l.direction, -wi)) / d2);
            }
            const float cosN = glm::dot(N, wi);
            if (cosN <= 0) continue;
            if (scene.occluded(x, wi, std::isfinite(dist) ? glm::length(l.position - x) : dist))
                continue;
            E += boundaryTransmittance(ior, cosN) * cosN * Li;
        }
        if (const raytrace::EnvironmentLight* env = scene.environment()) {
            // Stratified cosine-weighted directions: E = pi/K sum F_t L.
            const raytrace::Frame frame(N);
            const int side = std::max(1, int(std::lround(std::sqrt(double(envSamples)))));
            glm::vec3 sum(0.0f);
            for (int a = 0; a < side; ++a)
                for (int b = 0; b < side; ++b) {
                    glm::vec2 u((float(a) + 0.5f) / float(side), (float(b) + 0.5f) / float(side));
                    glm::vec3 wl = raytrace::sampleCosineHemisphere(u);
                    glm::vec3 w = frame.toWorld(wl);
                    if (scene.occluded(x, w, std::numeric_limits<float>::infinity())) continue;
                    sum += boundaryTransmittance(ior, wl.z) * env->radiance(w);
                }
            E += sum * (kPi / float(side * side));
        }
        E_[i] = E;
    }
}

glm::vec3 VnmShading::voxelRadiance(int out) const {
    const auto& sv = map_.surface();
    const glm::vec3 k = map_.falloff();
    const float reach = VoxelNumberMap::kNearField * map_.voxelSize();
    glm::vec3 near(0.0f), far(0.0f);
    for (size_t i = 0; i < sv.size(); ++i) {
        if (E_[i] == glm::vec3(0.0f) || !sv[i].exterior) continue;
        const float t = map_.tau(int(i), out);
        const glm::vec3 c =
            E_[i] * (sv[i].area * sv[i].kernelScale *
                     glm::vec3(std::exp(-k.x * t), std::exp(-k.y * t), std::exp(-k.z * t)));
        (glm::length(sv[i].position - sv[size_t(out)].position) <= reach ? near : far) += c;
    }
    return (far + sv[size_t(out)].nearScale * near) * scale_;
}

glm::vec3 VnmShading::scattered(const glm::vec3& p, const glm::vec3& wOut, bool smooth) const {
    std::vector<VoxelWeight> weights;
    if (smooth) {
        weights = map_.reconstructionAt(p);
    } else if (const int out = map_.surfaceVoxelAt(p); out >= 0) {
        weights = {{out, 1.0f}};
    }
    if (weights.empty()) return glm::vec3(0.0f);
    glm::vec3 L(0.0f), n(0.0f);
    for (const VoxelWeight& w : weights) {
        L += w.weight * voxelRadiance(w.voxel);
        n += w.weight * map_.surface()[size_t(w.voxel)].normal;
    }
    const float cosOut = glm::length(n) > 0 ? std::abs(glm::dot(glm::normalize(n), wOut)) : 1.0f;
    return L * boundaryTransmittance(medium_.ior, cosOut);
}

VnmImage renderVnm(const VoxelNumberMap& map, const TranslucentObject& object,
                   const raytrace::RayTracingScene& scene, const CameraIntrinsics& K,
                   const Pose& T_world_camera, int envSamples) {
    VnmShading shading(map, object, scene, envSamples);
    VnmImage img;
    img.radiance = cv::Mat(K.height, K.width, CV_32FC3, cv::Scalar::all(0));
    img.mask = cv::Mat(K.height, K.width, CV_8U, cv::Scalar(0));
    const glm::mat3 R(T_world_camera.rotationMatrix());
    const glm::vec3 eye(T_world_camera.translation);
    const raytrace::EnvironmentLight* env = scene.environment();
    const float ior = object.medium.ior;
    for (int y = 0; y < K.height; ++y)
        for (int x = 0; x < K.width; ++x) {
            auto dc = K.unproject({double(x), double(y)});
            if (!dc) continue;
            glm::vec3 d = glm::normalize(R * glm::vec3(*dc));
            raytrace::SurfaceHit hit;
            if (!scene.intersect(eye, d, std::numeric_limits<float>::infinity(), hit)) continue;
            if (!scene.medium(hit.geometry)) continue;
            img.mask.at<uint8_t>(y, x) = 255;
            glm::vec3 L = shading.scattered(hit.p, -d);
            const float cosF = std::abs(glm::dot(d, hit.ng));
            const float F = 1.0f - boundaryTransmittance(ior, cosF);
            if (env) {
                glm::vec3 n = glm::dot(d, hit.ng) < 0 ? hit.ng : -hit.ng;
                L += F * env->radiance(d - 2.0f * glm::dot(d, n) * n);
            }
            // The background straight through: the chord's optical thickness from the LUT.
            raytrace::SurfaceHit back;
            glm::vec3 o = hit.p + d * (1e-4f * std::max(1.0f, glm::length(hit.p)));
            if (scene.intersect(o, d, std::numeric_limits<float>::infinity(), back) &&
                scene.medium(back.geometry)) {
                int a = map.surfaceVoxelAt(hit.p), b = map.surfaceVoxelAt(back.p);
                float T = (1.0f - F) * boundaryTransmittance(ior, std::abs(glm::dot(d, back.ng)));
                if (a >= 0 && b >= 0) T *= std::exp(-map.tau(a, b));
                raytrace::SurfaceHit beyond;
                glm::vec3 o2 = back.p + d * (1e-4f * std::max(1.0f, glm::length(back.p)));
                if (!scene.intersect(o2, d, std::numeric_limits<float>::infinity(), beyond) && env)
                    L += T * env->radiance(d);
            }
            img.radiance.at<cv::Vec3f>(y, x) = {L.x, L.y, L.z};
        }
    return img;
}

}  // namespace mirage::translucency
