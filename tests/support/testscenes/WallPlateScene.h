#pragma once
// A real red wall lit by a real spot light, and a virtual white plate in front of it above the
// real floor: the plate blocks the light the wall bounces onto the floor under it (the imperfect
// shadow maps' and the L_rv / L_r routing's tests). World = glTF (metres, +Y up).
#include <glm/glm.hpp>

#include "testscenes/RenderTestScenes.h"

namespace mirage::test {

struct WallPlateScene {
    Scene scene;
    CameraIntrinsics cam = smallCamera();
    Pose pose = lookAtPose({0.9, 0.12, 0.2}, {-0.6, 0.05, 0.0});     // the floor under the plate
    glm::dvec3 plateLo{-0.88, 0.25, -0.6}, plateHi{-0.2, 0.3, 0.6};  // world (m)
};

inline WallPlateScene makeWallPlateScene() {
    WallPlateScene s;
    const int white = addMaterial(s.scene, glm::vec3(0.8f));
    const int red = addMaterial(s.scene, {0.9f, 0.2f, 0.2f});
    addFloor(s.scene, "floor", 0.0f, 4.0f, white, Origin::Real);
    addBox(s.scene, "wall", {-1.0f, 0.0f, -0.6f}, {-0.9f, 1.0f, 0.6f}, red, Origin::Real);
    addBox(s.scene, "plate", glm::vec3(s.plateLo), glm::vec3(s.plateHi), white, Origin::Virtual);
    addLight(s.scene, Light::Type::Spot, {0.5f, 0.6f, 0.0f},
             glm::normalize(glm::vec3(-0.9f, 0.6f, 0.0f) - glm::vec3(0.5f, 0.6f, 0.0f)), 10.0f,
             Origin::Real, 0.25f, 0.2f);
    return s;
}

}  // namespace mirage::test
