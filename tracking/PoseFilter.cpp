#include "tracking/PoseFilter.h"

#include <cmath>

namespace mirage::tracking {
namespace {

double alpha(double cutoffHz, double dt) {
    const double tau = 1.0 / (2.0 * M_PI * cutoffHz);
    return 1.0 / (1.0 + tau / dt);
}

// Rotation vector of a unit quaternion (shortest way: q and -q are the same rotation).
glm::dvec3 logQuat(glm::dquat q) {
    if (q.w < 0) q = -q;
    const glm::dvec3 v(q.x, q.y, q.z);
    const double s = glm::length(v);
    if (s < 1e-12) return 2.0 * v;
    return v * (2.0 * std::atan2(s, q.w) / s);
}

glm::dquat expRotation(const glm::dvec3& w) {
    const double a = glm::length(w);
    if (a < 1e-12) return glm::normalize(glm::dquat(1.0, 0.5 * w.x, 0.5 * w.y, 0.5 * w.z));
    return glm::angleAxis(a, w / a);
}

}  // namespace

Pose PoseFilter::update(const Pose& measured, double t) {
    if (!state_ || !(t > state_->t) || !measured.isFinite()) {
        state_ = State{measured, t, glm::dvec3(0.0), glm::dvec3(0.0)};
        return measured;
    }
    State& s = *state_;
    const double dt = t - s.t;
    const glm::dvec3 dT = measured.translation - s.filtered.translation;
    const glm::dvec3 dR = logQuat(glm::conjugate(s.filtered.rotation) * measured.rotation);
    const double aD = alpha(options_.derivativeCutoffHz, dt);
    // Low-pass the velocity vectors (as One Euro does per coordinate), then take their norms: at
    // rest the noise's velocities cancel instead of adding up as magnitudes would.
    s.velocityT += aD * (dT / dt - s.velocityT);
    s.velocityR += aD * (s.filtered.rotation * dR / dt - s.velocityR);  // world axes
    const double aT =
        alpha(options_.minCutoffHz + options_.translationBeta * glm::length(s.velocityT), dt);
    const double aR =
        alpha(options_.minCutoffHz + options_.rotationBeta * glm::length(s.velocityR), dt);
    s.filtered.translation += aT * dT;
    s.filtered.rotation = glm::normalize(s.filtered.rotation * expRotation(aR * dR));
    s.t = t;
    return s.filtered;
}

}  // namespace mirage::tracking
