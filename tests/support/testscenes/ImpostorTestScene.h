#pragma once
// The table-top scene of the impostor tests and benchmark (world = glTF frame, metres, +Y up):
// - a real grey floor (planar, 4 m square at y = 0) under everything;
// - a virtual mirror sphere (r 0.25 m at (0, 0.25, 0)) and a real glass sphere (r 0.15 m at
//   (0.9, 0.15, 0.8)): the specular objects (slots 0 and 1);
// - a virtual red box NEAR the mirror (10 cm gap on +X) or, with nearSphere, a finely tessellated
//   red sphere there; a real blue box far away on -X, a real green sphere behind on -Z;
// - optionally a real room without a ceiling (one non-planar mesh: four walls 1.5 m high at
//   +-2 m) that encloses both specular objects. Rays leaving upwards leave the modelled scene.
#include <cmath>
#include <string>

#include "core/scene/Scene.h"
#include "testscenes/RenderTestScenes.h"

namespace mirage::test {

// Four inward-facing walls of height h around [-half, half]^2 (one mesh, not planar).
inline void addRoomWalls(Scene& s, float half, float h, int material, Origin origin) {
    Primitive p;
    auto quad = [&](glm::vec3 n, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
        appendQuad(p, n, a, b, c, d);
    };
    const float H = half;
    quad({1, 0, 0}, {-H, 0, -H}, {-H, 0, H}, {-H, h, H}, {-H, h, -H});
    quad({-1, 0, 0}, {H, 0, -H}, {H, h, -H}, {H, h, H}, {H, 0, H});
    quad({0, 0, 1}, {-H, 0, -H}, {-H, h, -H}, {H, h, -H}, {H, 0, -H});
    quad({0, 0, -1}, {-H, 0, H}, {H, 0, H}, {H, h, H}, {-H, h, H});
    p.material = material;
    addMeshNode(s, "room walls", std::move(p), origin);
}

// nearSphere: the near object is a smooth red sphere (r 0.12 m at (0.47, 0.12, 0), 10 cm from the
// mirror) instead of the red box: curved, so the height-field refinement has work to do.
inline Scene impostorTestScene(bool withRoom, int sphereSegments = 24, bool nearSphere = false) {
    Scene s;
    const int grey = addMaterial(s, glm::vec3(0.6f));
    const int red = addMaterial(s, glm::vec3(0.8f, 0.1f, 0.1f));
    const int blue = addMaterial(s, glm::vec3(0.1f, 0.2f, 0.8f));
    const int green = addMaterial(s, glm::vec3(0.1f, 0.7f, 0.2f));
    const int wall = addMaterial(s, glm::vec3(0.7f, 0.7f, 0.5f));
    const int mirror = addMaterial(s, glm::vec3(0.95f), 0.0f, 1.0f);
    Material glass;
    glass.name = "glass";
    glass.baseColor = glm::vec4(1.0f);
    glass.roughness = 0.0f;
    glass.metallic = 0.0f;
    glass.transmission = 1.0f;
    glass.ior = 1.5f;
    s.materials.push_back(glass);
    const int glassMat = int(s.materials.size()) - 1;

    addFloor(s, "floor", 0.0f, 4.0f, grey, Origin::Real);
    addUvSphere(s, "mirror sphere", {0.0f, 0.25f, 0.0f}, 0.25f, mirror, Origin::Virtual,
                sphereSegments, 2 * sphereSegments);
    addUvSphere(s, "glass sphere", {0.9f, 0.15f, 0.8f}, 0.15f, glassMat, Origin::Real,
                sphereSegments, 2 * sphereSegments);
    if (nearSphere)
        addUvSphere(s, "near red sphere", {0.47f, 0.12f, 0.0f}, 0.12f, red, Origin::Virtual,
                    4 * sphereSegments, 2 * (4 * sphereSegments));
    else
        addBox(s, "near red box", {0.35f, 0.0f, -0.1f}, {0.55f, 0.3f, 0.1f}, red, Origin::Virtual);
    addBox(s, "far blue box", {-1.5f, 0.0f, 0.5f}, {-1.1f, 0.6f, 0.9f}, blue, Origin::Real);
    addUvSphere(s, "green sphere", {0.2f, 0.2f, -1.0f}, 0.2f, green, Origin::Real, sphereSegments,
                2 * sphereSegments);
    if (withRoom) addRoomWalls(s, 2.0f, 1.5f, wall, Origin::Real);
    return s;
}

}  // namespace mirage::test
