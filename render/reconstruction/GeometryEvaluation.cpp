#include "render/reconstruction/GeometryEvaluation.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <open3d/core/Tensor.h>
#include <open3d/t/geometry/RaycastingScene.h>

namespace mirage::reconstruction {
namespace {

struct WorldMesh {
    std::string name;
    std::vector<glm::vec3> positions;  // world
    std::vector<uint32_t> indices;
};

std::vector<WorldMesh> realMeshes(const Scene& scene) {
    std::vector<WorldMesh> out;
    for (const MeshInstance& inst : scene.meshInstances()) {
        if (inst.origin != Origin::Real) continue;
        WorldMesh m;
        m.name = scene.nodes[size_t(inst.node)].name;
        for (const Primitive& p : scene.meshes[size_t(inst.mesh)].primitives) {
            const auto base = uint32_t(m.positions.size());
            for (const auto& v : p.positions)
                m.positions.push_back(glm::vec3(inst.world * glm::dvec4(glm::dvec3(v), 1.0)));
            for (uint32_t i : p.indices) m.indices.push_back(base + i);
        }
        out.push_back(std::move(m));
    }
    return out;
}

// Uniform samples by area (a fixed seed: the same scene gives the same samples).
std::vector<glm::vec3> sampleSurface(const WorldMesh& m, double spacing) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    std::vector<glm::vec3> out;
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
        const glm::dvec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]],
                         c = m.positions[m.indices[t + 2]];
        const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
        const double expected = area / (spacing * spacing);
        int count = int(expected);
        if (uni(rng) < expected - count) ++count;
        for (int k = 0; k < count; ++k) {
            double r1 = uni(rng), r2 = uni(rng);
            if (r1 + r2 > 1) r1 = 1 - r1, r2 = 1 - r2;
            out.push_back(glm::vec3(a + r1 * (b - a) + r2 * (c - a)));
        }
    }
    return out;
}

class DistanceField {
public:
    explicit DistanceField(const std::vector<WorldMesh>& meshes) {
        for (const auto& m : meshes) {
            if (m.indices.empty()) continue;
            std::vector<float> v;
            for (const auto& p : m.positions) v.insert(v.end(), {p.x, p.y, p.z});
            std::vector<uint32_t> idx(m.indices);
            const auto nv = int64_t(m.positions.size()), nt = int64_t(idx.size() / 3);
            scene_.AddTriangles(open3d::core::Tensor(v, {nv, 3}, open3d::core::Float32),
                                open3d::core::Tensor(idx, {nt, 3}, open3d::core::UInt32));
            empty_ = false;
        }
    }
    std::vector<double> distances(const std::vector<glm::vec3>& points) {
        if (points.empty()) return {};
        if (empty_) return std::vector<double>(points.size(), 1e9);
        std::vector<float> q;
        for (const auto& p : points) q.insert(q.end(), {p.x, p.y, p.z});
        const auto d = scene_.ComputeDistance(
            open3d::core::Tensor(q, {int64_t(points.size()), 3}, open3d::core::Float32));
        const std::vector<float> values = d.ToFlatVector<float>();
        return std::vector<double>(values.begin(), values.end());
    }

private:
    open3d::t::geometry::RaycastingScene scene_;
    bool empty_ = true;
};

void summarise(std::vector<double> d, double threshold, double& within, double& meanMm,
               double& p95Mm) {
    if (d.empty()) return;
    double sum = 0;
    int in = 0;
    for (double x : d) sum += x, in += x <= threshold ? 1 : 0;
    within = double(in) / double(d.size());
    meanMm = 1000.0 * sum / double(d.size());
    std::sort(d.begin(), d.end());
    p95Mm = 1000.0 * d[size_t(0.95 * double(d.size() - 1))];
}

}  // namespace

GeometryScore evaluateGeometry(const Scene& truth, const Scene& rebuilt, const BoardPlane& plane,
                               const EvaluationOptions& o) {
    const std::vector<WorldMesh> trueMeshes = realMeshes(truth);
    const std::vector<WorldMesh> rebuiltMeshes = realMeshes(rebuilt);
    DistanceField toRebuilt(rebuiltMeshes), toTruth(trueMeshes);
    GeometryScore score;
    for (const WorldMesh& m : trueMeshes) {
        double top = -1e9, bottom = 1e9;
        for (const auto& p : m.positions) {
            const double h = plane.toPlane(glm::dvec3(p)).z;
            top = std::max(top, h), bottom = std::min(bottom, h);
        }
        // An object stands on the plane: its bottom near it, its top well above.
        if (top < o.objectMinHeightM || bottom < -o.objectMinHeightM || bottom > 0.05) continue;
        ObjectScore s;
        s.name = m.name;
        const auto samples = sampleSurface(m, o.sampleSpacingM);
        s.samples = int(samples.size());
        summarise(toRebuilt.distances(samples), o.thresholdM, s.completeness, s.meanMm, s.p95Mm);
        score.objects.push_back(s);
    }
    std::vector<glm::vec3> above;
    for (const WorldMesh& m : rebuiltMeshes)
        for (const auto& p : sampleSurface(m, o.sampleSpacingM))
            if (plane.toPlane(glm::dvec3(p)).z > o.objectMinHeightM) above.push_back(p);
    score.rebuiltSamples = int(above.size());
    summarise(toTruth.distances(above), o.thresholdM, score.accuracy, score.accuracyMeanMm,
              score.accuracyP95Mm);
    return score;
}

}  // namespace mirage::reconstruction
