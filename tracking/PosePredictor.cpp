#include "tracking/PosePredictor.h"

#include <algorithm>
#include <cmath>

#include "core/math/Pose.h"

namespace mirage::tracking {
namespace {

glm::dmat3 skew(const glm::dvec3& w) {
    // Column-major: m[c][r].
    return glm::dmat3(0, w.z, -w.y, -w.z, 0, w.x, w.y, -w.x, 0);
}

// The left Jacobian of SO(3), V(w) = I + (1 - cos a) / a^2 [w]x + (a - sin a) / a^3 [w]x^2: the
// translation of exp([w, v]) is V(w) v. Series below 1e-4 rad (the closed form loses digits).
glm::dmat3 leftJacobian(const glm::dvec3& w) {
    const double a = glm::length(w);
    const glm::dmat3 k = skew(w);
    double b, c;
    if (a < 1e-4) {
        b = 0.5 - a * a / 24.0;
        c = 1.0 / 6.0 - a * a / 120.0;
    } else {
        b = (1.0 - std::cos(a)) / (a * a);
        c = (a - std::sin(a)) / (a * a * a);
    }
    return glm::dmat3(1.0) + b * k + c * (k * k);
}

}  // namespace

PoseVelocity velocityBetween(const Pose& from, const Pose& to, double seconds) {
    const Pose delta = from.inverse() * to;  // the motion in `from`'s camera frame
    const glm::dvec3 w = rotationVector(delta.rotation);
    const glm::dvec3 v = glm::inverse(leftJacobian(w)) * delta.translation;
    return {w / seconds, v / seconds};
}

Pose extrapolatePose(const Pose& pose, const PoseVelocity& velocity, double seconds) {
    const glm::dvec3 w = velocity.angular * seconds, v = velocity.linear * seconds;
    Pose step;
    step.rotation = rotationFromVector(w);
    step.translation = leftJacobian(w) * v;
    Pose out = pose * step;
    out.rotation = glm::normalize(out.rotation);
    return out;
}

void PosePredictor::update(const Pose& pose, double t) {
    if (!pose.isFinite() || !std::isfinite(t)) {
        reset();
        return;
    }
    velocity_.reset();
    if (last_ && t > lastT_ && t - lastT_ <= options_.maxGapS) {
        const PoseVelocity v = velocityBetween(*last_, pose, t - lastT_);
        const double speed = glm::length(pose.translation - last_->translation) / (t - lastT_);
        if (speed <= options_.maxSpeedMps && glm::length(v.angular) <= options_.maxTurnRadps)
            velocity_ = v;
    }
    last_ = pose;
    lastT_ = t;
}

void PosePredictor::reset() {
    last_.reset();
    velocity_.reset();
    lastT_ = 0;
}

double PosePredictor::horizon(double t) const {
    if (!last_ || !std::isfinite(t)) return 0.0;
    return std::clamp(t - lastT_, 0.0, options_.maxAheadS);
}

std::optional<Pose> PosePredictor::predict(double t) const {
    if (!last_) return std::nullopt;
    if (!velocity_) return last_;
    return extrapolatePose(*last_, *velocity_, horizon(t));
}

}  // namespace mirage::tracking
