#pragma once
// A dark virtual box turned 30 degrees about +Y on a real table (3 m), lit by a real spot light,
// seen obliquely: straight silhouette and shadow edges at an angle to the pixel grid and to the
// shadow map's texels (the anti-aliasing and shadow-edge tests). World = glTF (metres, +Y up).
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "testscenes/CausticTestScenes.h"

namespace mirage::test {

struct TurnedBoxScene {
    Scene scene;
    CameraIntrinsics cam;
    Pose pose;
    glm::vec3 boxLo{-0.08f, 0.0f, -0.08f}, boxHi{0.08f, 0.12f, 0.08f};  // box frame (m)
    glm::dmat4 boxWorld{1.0};  // box frame -> world: 30 degrees about +Y
    glm::vec3 lightPos{0.6f, 0.5f, 0.3f};
    Light::Type lightType = Light::Type::Spot;

    // The end of the segment from a table point p towards the light: the light itself, or 10 m
    // up the directional light's rays.
    glm::dvec3 towardsLight(const glm::dvec3& p) const {
        if (lightType != Light::Type::Directional) return glm::dvec3(lightPos);
        return p + 10.0 * glm::normalize(glm::dvec3(lightPos));
    }
};

// `light`: the spot (default), a point light at the spot's position, or a directional light
// along the spot's axis with about the spot's irradiance at the box; placed at `lightPos`
// (world, m) and aimed at the world origin.
inline TurnedBoxScene makeTurnedBoxScene(Light::Type light = Light::Type::Spot,
                                         glm::vec3 lightPos = {0.6f, 0.5f, 0.3f}) {
    TurnedBoxScene s;
    s.lightType = light;
    s.lightPos = lightPos;
    const int table = addMaterial(s.scene, glm::vec3(0.7f));
    const int dark = addMaterial(s.scene, glm::vec3(0.04f));
    addFloor(s.scene, "table", 0.0f, 3.0f, table, Origin::Real);
    addBox(s.scene, "box", s.boxLo, s.boxHi, dark, Origin::Virtual);
    s.boxWorld = glm::rotate(glm::dmat4(1.0), glm::radians(30.0), glm::dvec3(0, 1, 0));
    s.scene.nodes.back().local = s.scene.nodes.back().world = s.boxWorld;
    const float intensity = light == Light::Type::Directional ? 6.0f : 4.0f;  // W/m^2 or W/sr
    addLight(s.scene, light, s.lightPos, -s.lightPos, intensity, Origin::Real, 0.6f, 0.5f);
    s.cam = smallCamera(240, 180, 360.0);
    s.pose = lookAtPose({-0.40, 0.45, -0.30}, {-0.1, 0.0, -0.05});
    return s;
}

// Does the world segment a-b cross the (turned) box?
inline bool segmentHitsBox(const TurnedBoxScene& s, glm::dvec3 a, glm::dvec3 b) {
    const glm::dmat4 inv = glm::inverse(s.boxWorld);
    return segmentHitsBox(glm::dvec3(inv * glm::dvec4(a, 1.0)),
                          glm::dvec3(inv * glm::dvec4(b, 1.0)), glm::dvec3(s.boxLo),
                          glm::dvec3(s.boxHi));
}

}  // namespace mirage::test
