#pragma once
// Camera poses for synthetic views, shared by the render and tracking tests and benchmarks.
#include <cmath>

#include <glm/glm.hpp>

#include "core/math/Pose.h"

namespace mirage::test {

// T_world_camera (OpenCV camera axes: +X right, +Y down, +Z forward) at `eye` looking at
// `target`; `up` is the world direction that appears up in the image; `rollRad` turns the
// camera about its optical axis.
inline Pose lookAt(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up,
                   double rollRad = 0.0) {
    const glm::dvec3 fwd = glm::normalize(target - eye);
    glm::dvec3 right = glm::normalize(glm::cross(fwd, up));
    glm::dvec3 down = glm::cross(fwd, right);
    const glm::dvec3 r2 = std::cos(rollRad) * right + std::sin(rollRad) * down;
    down = glm::cross(fwd, r2);
    return Pose::fromRotationTranslation(glm::dmat3(r2, down, fwd), eye);
}

}  // namespace mirage::test
