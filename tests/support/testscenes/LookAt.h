#pragma once
// Camera poses for synthetic views, shared by the render and tracking tests and benchmarks.
#include <cmath>

#include <glm/glm.hpp>

#include "core/math/Pose.h"

namespace mirage::test {

// T_world_camera (OpenCV camera axes: +X right, +Y down, +Z forward) at `eye` looking at
// `target`: core's cameraLookingAt.
inline Pose lookAt(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up,
                   double rollRad = 0.0) {
    return cameraLookingAt(eye, target, up, rollRad);
}

}  // namespace mirage::test
