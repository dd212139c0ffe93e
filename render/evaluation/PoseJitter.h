#pragma once
// Tracking-like noise on a camera pose: what a tracked camera's pose does from frame to frame
// while the camera stands still (docs/tracking.md: fractions of a millimetre, hundredths of a
// degree). `mirage bench --knob pose_jitter=MM` and the temporal-smoothing tests render a static
// scene through it, so that what shimmers under tracking noise can be measured.
#include <cmath>
#include <cstdint>
#include <random>

#include <glm/gtc/quaternion.hpp>

#include "core/math/Pose.h"

namespace mirage::render {

// T_world_camera moved by a Gaussian translation of sigmaMm millimetres per world axis and turned
// by a Gaussian rotation of sigmaDeg degrees about each camera axis, drawn from `seed` alone (the
// same seed gives the same pose, in any process).
inline Pose jitteredPose(const Pose& T_world_camera, double sigmaMm, double sigmaDeg,
                         uint64_t seed) {
    std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + 0x2545F4914F6CDD1Dull);
    std::normal_distribution<double> n(0.0, 1.0);
    const glm::dvec3 t(n(rng), n(rng), n(rng));
    const glm::dvec3 r(n(rng), n(rng), n(rng));
    const glm::dvec3 axisAngle = r * (sigmaDeg * M_PI / 180.0);  // camera frame, radians
    const double angle = glm::length(axisAngle);
    Pose T_camera_jittered;
    if (angle > 0.0) T_camera_jittered.rotation = glm::angleAxis(angle, axisAngle / angle);
    Pose out = T_world_camera * T_camera_jittered;
    out.translation += t * (sigmaMm * 1e-3);
    return out;
}

}  // namespace mirage::render
