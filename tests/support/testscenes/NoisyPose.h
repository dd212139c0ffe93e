#pragma once
// A pose with Gaussian noise: sigmaM (metres) per axis on the position, sigmaRad (radians) per
// axis of a rotation vector applied in the world frame, drawn from `rng`.
#include <random>

#include "core/math/Pose.h"

namespace mirage::test {

inline Pose noisyPose(const Pose& p, std::mt19937& rng, double sigmaM, double sigmaRad) {
    std::normal_distribution<double> n(0.0, 1.0);
    Pose q = p;
    q.translation += sigmaM * glm::dvec3(n(rng), n(rng), n(rng));
    const glm::dvec3 w = sigmaRad * glm::dvec3(n(rng), n(rng), n(rng));
    q.rotation = glm::normalize(rotationFromVector(w) * q.rotation);
    return q;
}

}  // namespace mirage::test
