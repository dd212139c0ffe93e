#pragma once
// Rigid transforms and the frame conventions of mirage (docs/conventions.md).
//
// A pose named T_a_b maps points from frame b into frame a:  p_a = R * p_b + t.
// So T_world_camera holds the camera's position in the world as its translation, and
// T_a_c = T_a_b * T_b_c. Units are metres; angles in radians unless a name says _deg.
//
// Camera frames follow OpenCV: +X right, +Y down, +Z forward (the direction the camera looks).
// glTF cameras look down -Z with +Y up; kCvFromGltfCamera converts between the two.
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace mirage {

struct Pose {
    glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  // unit quaternion (w, x, y, z)
    glm::dvec3 translation{0.0};

    static Pose identity() { return {}; }
    // From a rigid 4x4 matrix (column-major, glm). The rotation part is re-orthonormalised.
    static Pose fromMatrix(const glm::dmat4& m);
    static Pose fromRotationTranslation(const glm::dmat3& r, const glm::dvec3& t);

    glm::dmat4 matrix() const;
    glm::dmat3 rotationMatrix() const { return glm::mat3_cast(rotation); }
    glm::dvec3 operator*(const glm::dvec3& p) const { return rotation * p + translation; }
    Pose operator*(const Pose& o) const;  // T_a_b * T_b_c = T_a_c
    Pose inverse() const;
    bool isFinite() const;
};

// T_world_camera (OpenCV camera axes) at `eye` looking at `target`; `up` is the world direction
// that appears up in the image; `rollRad` turns the camera about its optical axis.
Pose cameraLookingAt(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up,
                     double rollRad = 0.0);

// Angle of the rotation between a and b (radians, in [0, pi]).
double rotationAngleBetween(const glm::dquat& a, const glm::dquat& b);

// The rotation vector (axis x angle, radians) of a unit quaternion, the shorter way round (q and
// -q are the same rotation): the logarithm of SO(3). Near identity it is 2 (x, y, z).
glm::dvec3 rotationVector(glm::dquat q);
// The unit quaternion of a rotation vector (axis x angle, radians): the exponential of SO(3).
glm::dquat rotationFromVector(const glm::dvec3& w);

// Rotation taking OpenCV camera axes to glTF camera axes (and back: it is its own inverse):
// x stays, y and z flip. T_world_cvcam = T_world_gltfcam * kCvFromGltfCamera.
inline const Pose kCvFromGltfCamera =
    Pose::fromRotationTranslation(glm::dmat3(1, 0, 0, 0, -1, 0, 0, 0, -1), glm::dvec3(0.0));

}  // namespace mirage
