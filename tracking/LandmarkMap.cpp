#include "tracking/LandmarkMap.h"

#include <algorithm>
#include <cmath>

namespace mirage::tracking {
namespace {

// Tangent axes perpendicular to a unit direction.
void tangentAxes(const glm::dvec3& d, glm::dvec3& e1, glm::dvec3& e2) {
    const glm::dvec3 ref = std::abs(d.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    e1 = glm::normalize(glm::cross(ref, d));
    e2 = glm::cross(d, e1);
}

}  // namespace

int LandmarkMap::add(const CameraIntrinsics& camera, const Pose& T_world_camera,
                     const glm::dvec2& pixel, double pixelSigma, double rotSigmaRad,
                     double posSigmaM, double depthGuessM, double rhoSigmaFraction, bool derived) {
    const auto ray = camera.unproject(pixel);
    if (!ray || !(depthGuessM > 0)) return -1;
    Landmark l;
    l.id = nextId_++;
    l.anchor = T_world_camera.translation;
    l.direction = glm::normalize(T_world_camera.rotation * *ray);
    tangentAxes(l.direction, l.e1, l.e2);
    l.rho = l.rhoPrior = 1.0 / depthGuessM;
    l.rhoPriorSigma = rhoSigmaFraction * l.rhoPrior;
    // Direction: the pixel noise over the focal length, plus the creating pose's rotation error.
    const double f = 0.5 * (camera.fx + camera.fy);
    const double angle2 = (pixelSigma / f) * (pixelSigma / f) + rotSigmaRad * rotSigmaRad;
    l.covariance = {angle2, 0, 0, 0, angle2, 0, 0, 0, l.rhoPriorSigma * l.rhoPriorSigma};
    l.anchorSigmaM = posSigmaM;
    l.derived = derived;
    l.observations.push_back({T_world_camera, pixel, std::hypot(pixelSigma, f * rotSigmaRad)});
    landmarks_.push_back(l);
    return l.id;
}

Landmark* LandmarkMap::find(int id) {
    // Ids grow with the position in the vector: binary search.
    auto it = std::lower_bound(landmarks_.begin(), landmarks_.end(), id,
                               [](const Landmark& l, int v) { return l.id < v; });
    return it != landmarks_.end() && it->id == id ? &*it : nullptr;
}

void LandmarkMap::remove(int id) {
    auto it = std::lower_bound(landmarks_.begin(), landmarks_.end(), id,
                               [](const Landmark& l, int v) { return l.id < v; });
    if (it != landmarks_.end() && it->id == id) landmarks_.erase(it);
}

void LandmarkMap::observe(int id, const CameraIntrinsics& camera, const LandmarkObservation& o,
                          double minBaselineM, double minTurnRad) {
    Landmark* l = find(id);
    if (!l) return;
    // Only views that add geometry: a camera that stayed where a stored view was adds nothing
    // but cost.
    for (const auto& s : l->observations)
        if (glm::length(s.T_world_camera.translation - o.T_world_camera.translation) <
                minBaselineM &&
            rotationAngleBetween(s.T_world_camera.rotation, o.T_world_camera.rotation) < minTurnRad)
            return;
    if (l->observations.size() >= kMaxObservations) {
        // Keep the first (the anchor's) and drop the one nearest to its successor in position.
        size_t drop = 1;
        double best = 1e18;
        for (size_t i = 1; i + 1 < l->observations.size(); ++i) {
            const double d = glm::length(l->observations[i].T_world_camera.translation -
                                         l->observations[i + 1].T_world_camera.translation);
            if (d < best) best = d, drop = i;
        }
        l->observations.erase(l->observations.begin() + long(drop));
    }
    l->observations.push_back(o);
    refine(camera, *l);
}

void LandmarkMap::refine(const CameraIntrinsics& camera, Landmark& l) const {
    // Gauss-Newton on (angle about e1, angle about e2, rho): residuals (projection - pixel) /
    // sigma per observation, and (rho - rhoPrior) / rhoPriorSigma.
    const double rotFloor2 = l.covariance[0];  // kept: the creating pose's share does not shrink
    glm::dmat3 JtJ(0.0);
    for (int iter = 0; iter < 4; ++iter) {
        JtJ = glm::dmat3(0.0);
        glm::dvec3 Jtr(0.0);
        double cost = 0;
        int used = 0;
        for (const auto& o : l.observations) {
            const glm::dmat3 Rt = glm::transpose(o.T_world_camera.rotationMatrix());
            const glm::dvec3 h = l.homogeneous(o.T_world_camera.translation);
            glm::dmat3x2 dp;
            const auto px = camera.projectWithJacobian(Rt * h, dp);
            if (!px) continue;
            const double w = 1.0 / std::max(1e-6, o.sigmaPx);
            const glm::dvec2 r = (*px - o.pixel) * w;
            const glm::dvec3 dh[3] = {l.e1, l.e2, l.anchor - o.T_world_camera.translation};
            glm::dvec2 J[3];
            for (int k = 0; k < 3; ++k) J[k] = dp * (Rt * dh[k]) * w;
            for (int a = 0; a < 3; ++a) {
                Jtr[a] += glm::dot(J[a], r);
                for (int b = 0; b < 3; ++b) JtJ[a][b] += glm::dot(J[a], J[b]);
            }
            cost += glm::dot(r, r) * o.sigmaPx * o.sigmaPx;
            ++used;
        }
        l.rmsPx = used ? std::sqrt(cost / used) : 0;
        const double wp = 1.0 / std::max(1e-12, l.rhoPriorSigma);
        JtJ[2][2] += wp * wp;
        Jtr[2] += (l.rho - l.rhoPrior) * wp * wp;
        if (std::abs(glm::determinant(JtJ)) < 1e-300) return;
        const glm::dvec3 step = -(glm::inverse(JtJ) * Jtr);
        l.direction = glm::normalize(l.direction + step[0] * l.e1 + step[1] * l.e2);
        tangentAxes(l.direction, l.e1, l.e2);
        l.rho = std::max(0.0, l.rho + step[2]);
        if (glm::length(glm::dvec2(step[0], step[1])) < 1e-9 && std::abs(step[2]) < 1e-9 * l.rho)
            break;
    }
    const glm::dmat3 C = glm::inverse(JtJ);
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) l.covariance[size_t(a * 3 + b)] = C[a][b];
    // The observations' pose errors are shared by all of them (they come from the same board):
    // the direction cannot become more certain than the pose that anchored it.
    l.covariance[0] = std::max(l.covariance[0], rotFloor2);
    l.covariance[4] = std::max(l.covariance[4], rotFloor2);
}

}  // namespace mirage::tracking
