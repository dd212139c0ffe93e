#include "render/passes/impostor/ImpostorAccuracy.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "core/Error.h"

namespace mirage::render {
namespace {

struct WorldTriangle {
    glm::vec3 a, b, c;     // world (m)
    glm::vec3 na, nb, nc;  // world vertex normals (unit or zero)
};

}  // namespace

std::vector<ImpostorRay> sampleSpecularSurfaceRays(const Scene& scene, const GpuScene& gpu,
                                                   int count, uint32_t seed) {
    // Draw items in GpuScene's order: instances, then their non-empty primitives.
    std::vector<std::vector<WorldTriangle>> drawTris;
    for (const MeshInstance& inst : scene.meshInstances()) {
        if (inst.mesh < 0 || size_t(inst.mesh) >= scene.meshes.size()) continue;
        const glm::dmat4& W = inst.world;
        const glm::dmat3 N = glm::transpose(glm::inverse(glm::dmat3(W)));
        for (const Primitive& p : scene.meshes[size_t(inst.mesh)].primitives) {
            if (p.positions.empty() || p.indices.empty()) continue;
            std::vector<WorldTriangle> tris;
            auto P = [&](uint32_t i) { return glm::vec3(W * glm::dvec4(p.positions[i], 1.0)); };
            auto Nn = [&](uint32_t i) {
                if (i >= p.normals.size()) return glm::vec3(0.0f);
                const glm::dvec3 n = N * glm::dvec3(p.normals[i]);
                const double l = glm::length(n);
                return l > 0 ? glm::vec3(n / l) : glm::vec3(0.0f);
            };
            for (size_t i = 0; i + 2 < p.indices.size(); i += 3) {
                const uint32_t a = p.indices[i], b = p.indices[i + 1], c = p.indices[i + 2];
                tris.push_back({P(a), P(b), P(c), Nn(a), Nn(b), Nn(c)});
            }
            drawTris.push_back(std::move(tris));
        }
    }
    MR_CHECK(drawTris.size() == gpu.draws().size(),
             "sampleSpecularSurfaceRays: the scene is not the one the GpuScene was built from");

    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> U(0.0f, 1.0f);
    std::vector<ImpostorRay> rays;
    const std::vector<int>& specular = gpu.specularDraws();
    for (size_t slot = 0; slot < specular.size(); ++slot) {
        const std::vector<WorldTriangle>& tris = drawTris[size_t(specular[slot])];
        std::vector<double> cdf;
        double total = 0.0;
        for (const WorldTriangle& t : tris) {
            total += 0.5 * glm::length(glm::cross(t.b - t.a, t.c - t.a));
            cdf.push_back(total);
        }
        if (total <= 0.0) continue;
        const glm::vec3 centre = gpu.draws()[size_t(specular[slot])].bounds.center;
        for (int i = 0; i < count; ++i) {
            const double target = U(rng) * total;
            size_t k = size_t(std::lower_bound(cdf.begin(), cdf.end(), target) - cdf.begin());
            k = std::min(k, tris.size() - 1);
            const WorldTriangle& t = tris[k];
            float u = U(rng), v = U(rng);
            if (u + v > 1.0f) u = 1.0f - u, v = 1.0f - v;
            const glm::vec3 p = t.a + u * (t.b - t.a) + v * (t.c - t.a);
            glm::vec3 n = (1.0f - u - v) * t.na + u * t.nb + v * t.nc;
            if (glm::dot(n, n) < 1e-12f) n = glm::cross(t.b - t.a, t.c - t.a);
            n = glm::normalize(n);
            if (glm::dot(n, p - centre) < 0.0f) n = -n;  // outward (closed, star-shaped objects)
            // Uniform direction on the hemisphere around n.
            const float z = U(rng), phi = 2.0f * float(M_PI) * U(rng);
            const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
            const glm::vec3 a = std::abs(n.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
            const glm::vec3 tx = glm::normalize(glm::cross(a, n)), ty = glm::cross(n, tx);
            const glm::vec3 d =
                glm::normalize(tx * (r * std::cos(phi)) + ty * (r * std::sin(phi)) + n * z);
            rays.push_back({p + n * 1e-4f, d, int(slot)});
        }
    }
    return rays;
}

std::vector<ExactHit> castExact(const std::vector<ImpostorRay>& rays, const GpuScene& gpu,
                                const raytrace::RayTracingScene& exact) {
    MR_CHECK(
        exact.subset() == raytrace::SceneSubset::All && exact.geometryCount() == gpu.draws().size(),
        "castExact: the Embree scene must hold all geometry of the GpuScene's scene");
    std::vector<ExactHit> out(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) {
        const ImpostorRay& r = rays[i];
        const uint32_t self = uint32_t(gpu.specularDraws()[size_t(r.specularSlot)]);
        glm::vec3 o = r.origin;
        for (int guard = 0; guard < 16; ++guard) {
            raytrace::SurfaceHit h;
            if (!exact.intersect(o, r.direction, 1e30f, h)) break;
            if (h.geometry == self) {  // its own surface: not part of its surroundings
                o = h.p + r.direction * 1e-4f;
                continue;
            }
            out[i].hit = true;
            out[i].position = h.p;
            out[i].origin = exact.origin(h) == Origin::Real ? kOriginReal : kOriginVirtual;
            out[i].draw = int(h.geometry);
            break;
        }
    }
    return out;
}

ImpostorAccuracy compareHits(const std::vector<ImpostorHit>& traced,
                             const std::vector<ExactHit>& exact) {
    MR_CHECK(traced.size() == exact.size(), "compareHits: ray counts differ");
    ImpostorAccuracy a;
    a.rays = int(traced.size());
    a.errorsMm.assign(traced.size(), -1.0);
    std::vector<double> errs;
    int sameOrigin = 0;
    for (size_t i = 0; i < traced.size(); ++i) {
        const bool t = traced[i].hit, e = exact[i].hit;
        if (t && e) {
            ++a.bothHit;
            double err = 1000.0 * double(glm::length(traced[i].position - exact[i].position));
            if (!std::isfinite(err)) err = 1e9;  // a NaN position counts as a huge error
            a.errorsMm[i] = err;
            errs.push_back(err);
            sameOrigin += traced[i].origin == exact[i].origin;
        } else if (!t && !e) {
            ++a.bothMiss;
        } else if (t) {
            ++a.falseHit;
        } else {
            ++a.falseMiss;
        }
    }
    if (a.rays > 0) a.hitMissAgreement = double(a.bothHit + a.bothMiss) / a.rays;
    if (!errs.empty()) {
        std::sort(errs.begin(), errs.end());
        a.medianErrorMm = errs[errs.size() / 2];
        a.p90ErrorMm = errs[std::min(errs.size() - 1, size_t(0.9 * double(errs.size())))];
        double sum = 0;
        for (double e : errs) sum += e;
        a.meanErrorMm = sum / double(errs.size());
        a.originAgreement = double(sameOrigin) / double(errs.size());
    }
    return a;
}

}  // namespace mirage::render
