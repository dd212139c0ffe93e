#include "core/math/Pose.h"

#include <cmath>

namespace mirage {

Pose Pose::fromMatrix(const glm::dmat4& m) {
    return fromRotationTranslation(glm::dmat3(m), glm::dvec3(m[3]));
}

Pose cameraLookingAt(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up,
                     double rollRad) {
    const glm::dvec3 fwd = glm::normalize(target - eye);
    const glm::dvec3 right = glm::normalize(glm::cross(fwd, up));
    const glm::dvec3 down = glm::cross(fwd, right);
    const glm::dvec3 rolledRight = std::cos(rollRad) * right + std::sin(rollRad) * down;
    return Pose::fromRotationTranslation(glm::dmat3(rolledRight, glm::cross(fwd, rolledRight), fwd),
                                         eye);
}

Pose Pose::fromRotationTranslation(const glm::dmat3& r, const glm::dvec3& t) {
    Pose p;
    // quat_cast followed by normalisation is a projection onto the nearest rotation for the
    // nearly-orthonormal matrices we get from composed transforms.
    p.rotation = glm::normalize(glm::quat_cast(r));
    p.translation = t;
    return p;
}

glm::dmat4 Pose::matrix() const {
    glm::dmat4 m(glm::mat3_cast(rotation));
    m[3] = glm::dvec4(translation, 1.0);
    return m;
}

Pose Pose::operator*(const Pose& o) const {
    Pose p;
    p.rotation = glm::normalize(rotation * o.rotation);
    p.translation = rotation * o.translation + translation;
    return p;
}

Pose Pose::inverse() const {
    Pose p;
    p.rotation = glm::conjugate(rotation);
    p.translation = -(p.rotation * translation);
    return p;
}

bool Pose::isFinite() const {
    for (int i = 0; i < 4; ++i)
        if (!std::isfinite(rotation[i])) return false;
    for (int i = 0; i < 3; ++i)
        if (!std::isfinite(translation[i])) return false;
    return true;
}

double rotationAngleBetween(const glm::dquat& a, const glm::dquat& b) {
    // |w| of the relative rotation; abs() because q and -q are the same rotation.
    double w = std::abs(glm::dot(glm::normalize(a), glm::normalize(b)));
    return 2.0 * std::acos(std::min(1.0, w));
}

glm::dvec3 rotationVector(glm::dquat q) {
    if (q.w < 0) q = -q;
    const glm::dvec3 v(q.x, q.y, q.z);
    const double s = glm::length(v);
    // Below 1e-12 (sin of half the angle) the first-order term, without dividing by s.
    if (s < 1e-12) return 2.0 * v;
    return v * (2.0 * std::atan2(s, q.w) / s);
}

glm::dquat rotationFromVector(const glm::dvec3& w) {
    const double a = glm::length(w);
    if (a < 1e-12) return glm::normalize(glm::dquat(1.0, 0.5 * w.x, 0.5 * w.y, 0.5 * w.z));
    return glm::angleAxis(a, w / a);
}

}  // namespace mirage
