#pragma once
// Scenes for light through glass (shadows through glass, caustics; Knecht 2013 Sec. 4.2, 5.2): a
// real diffuse table, a glass sphere above it (or a plate, or a block), one light above and to
// the side so the glass's shadow and caustic fall on the table where the camera sees them. World =
// glTF (metres, +Y up); poses T_world_camera with OpenCV axes.
#include <algorithm>
#include <cmath>
#include <optional>

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include "testscenes/SpecularTestScenes.h"

namespace mirage::test {

enum class CausticObject { Sphere, Slab, Block };

struct CausticScene {
    Scene scene;
    CausticObject object = CausticObject::Sphere;
    glm::vec3 boxLo{0.0f}, boxHi{0.0f};  // slab / block bounds (world, m)
    // The sphere (r = 0.1 m, IOR 1.5: focal length 1.5 r from its centre) floats 7.5 cm above the
    // table; the light, 1 m away at 60 degrees elevation, is focused 0.2 m behind the centre,
    // just past the focus: a bright caustic about 7 cm wide on the table, on the camera's side.
    CameraIntrinsics cam = smallCamera(128, 96, 150.0);
    Pose pose = lookAtPose({-0.8, 0.6, 0.6}, {-0.1, 0.05, 0.0});
    glm::vec3 sphereCentre{0.0f, 0.175f, 0.0f};
    float sphereRadius = 0.1f;
    glm::vec3 lightPos{0.5f, 1.041f, 0.0f};
    // The mirror of CausticSceneOptions::mirror (world box, m): its front face is z = mirrorHi.z.
    glm::vec3 mirrorLo{-0.55f, 0.005f, -0.31f}, mirrorHi{0.2f, 0.4f, -0.3f};
};

struct CausticSceneOptions {
    Light::Type lightType = Light::Type::Spot;
    bool lightReal = true, sphereReal = false, tableReal = true;
    float ior = 1.5f;
    glm::vec3 attenuationColor{1.0f};
    float attenuationDistance = INFINITY;
    float intensity = 3.0f;
    CausticObject object = CausticObject::Sphere;
    // Overrides (when set): light position, sphere centre / radius.
    std::optional<glm::vec3> lightPos, sphereCentre;
    std::optional<float> sphereRadius;
    float tableSize = 3.0f;
    // A virtual mirror (a 1 cm plate standing on the table behind the caustic, facing +Z) that
    // shows the table's caustic to the camera of mirrorView(); the spot's cone is then narrowed
    // to the sphere (outer 0.15 rad) so the mirror itself stays out of it.
    bool mirror = false;
};

inline CausticScene makeCausticScene(const CausticSceneOptions& o) {
    CausticScene s;
    const int table = addMaterial(s.scene, glm::vec3(0.7f));
    const int glass = addGlass(s.scene, o.ior, o.attenuationColor, o.attenuationDistance);
    if (o.lightPos) s.lightPos = *o.lightPos;
    if (o.sphereCentre) s.sphereCentre = *o.sphereCentre;
    if (o.sphereRadius) s.sphereRadius = *o.sphereRadius;
    s.object = o.object;
    addFloor(s.scene, "table", 0.0f, o.tableSize, table,
             o.tableReal ? Origin::Real : Origin::Virtual);
    const Origin objectOrigin = o.sphereReal ? Origin::Real : Origin::Virtual;
    if (o.object == CausticObject::Sphere) {
        addUvSphere(s.scene, "glass sphere", s.sphereCentre, s.sphereRadius, glass, objectOrigin,
                    48, 64);
    } else {
        // A glass plate held 0.2 m above the table (2 cm thick), or a 15 cm block on it.
        const bool slab = o.object == CausticObject::Slab;
        s.boxLo = slab ? glm::vec3(-0.15f, 0.2f, -0.15f) : glm::vec3(-0.1f, 0.0f, -0.1f);
        s.boxHi = slab ? glm::vec3(0.15f, 0.22f, 0.15f) : glm::vec3(0.1f, 0.15f, 0.1f);
        addBox(s.scene, slab ? "glass plate" : "glass block", s.boxLo, s.boxHi, glass,
               objectOrigin);
        s.sphereCentre = 0.5f * (s.boxLo + s.boxHi);
        s.sphereRadius = 0.5f * glm::length(s.boxHi - s.boxLo);
    }
    if (o.mirror)
        addBox(s.scene, "mirror", s.mirrorLo, s.mirrorHi, addMirror(s.scene), Origin::Virtual);
    addLight(s.scene, o.lightType, s.lightPos, glm::normalize(s.sphereCentre - s.lightPos),
             o.intensity, o.lightReal ? Origin::Real : Origin::Virtual, o.mirror ? 0.15f : 0.5f,
             o.mirror ? 0.12f : 0.4f);
    return s;
}

// The camera of a scene with the mirror (CausticSceneOptions::mirror): looking down at the
// mirror past the sphere, so that the table's caustic is seen in the mirror (and directly).
inline void mirrorView(CausticScene& s, int width, int height, double f) {
    s.cam = smallCamera(width, height, f);
    s.pose = lookAtPose({-0.45, 0.4, 0.7}, {-0.15, 0.06, -0.25});
}

// Does the segment a -> b pass within r of c?
inline bool segmentNearPoint(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, double r) {
    const glm::dvec3 ab = b - a;
    const double t = std::clamp(glm::dot(c - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
    return glm::length(a + t * ab - c) < r;
}

// Table pixels (y = 0 plane) whose straight line to the light passes through the glass shrunk
// by `inner` about its centre (1 = the geometric shadow), not covered by the glass in the camera
// (the sphere plus 1.5 px; the box's projection plus a 1 cm margin). CV_8U 255 / 0.
inline cv::Mat straightShadowMask(const CausticScene& s, double inner = 0.9) {
    cv::Mat m(s.cam.height, s.cam.width, CV_8U, cv::Scalar(0));
    const glm::dvec3 eye = s.pose.translation;
    const glm::dvec3 c(s.sphereCentre);
    for (int y = 0; y < m.rows; ++y)
        for (int x = 0; x < m.cols; ++x) {
            const glm::dvec3 rayCam = glm::normalize(
                glm::dvec3((x - s.cam.cx) / s.cam.fx, (y - s.cam.cy) / s.cam.fy, 1.0));
            const glm::dvec3 d = s.pose.rotation * rayCam;
            if (d.y >= -1e-6) continue;
            const glm::dvec3 q = eye + d * (-eye.y / d.y);
            if (s.object != CausticObject::Sphere) {
                const glm::dvec3 lo(s.boxLo), hi(s.boxHi), margin(0.01);
                if (segmentHitsBox(eye, q, lo - margin, hi + margin)) continue;
                const glm::dvec3 mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo) * inner;
                if (segmentHitsBox(q, glm::dvec3(s.lightPos), mid - half, mid + half))
                    m.at<uint8_t>(y, x) = 255;
                continue;
            }
            const double angPx = 1.5 / s.cam.fx;  // the sphere's silhouette plus 1.5 px
            const glm::dvec3 toC = c - eye;
            const double ang = std::acos(std::clamp(glm::dot(d, glm::normalize(toC)), -1.0, 1.0));
            if (ang < std::asin(std::min(1.0, s.sphereRadius / glm::length(toC))) + angPx) continue;
            if (segmentNearPoint(q, glm::dvec3(s.lightPos), c, inner * s.sphereRadius))
                m.at<uint8_t>(y, x) = 255;
        }
    return m;
}

// The caustic scene's camera and glass sphere as a specular test view (the sphere's pixel mask).
inline SpecularScene sphereView(const CausticScene& s) {
    SpecularScene v;
    v.cam = s.cam;
    v.pose = s.pose;
    v.sphereCentre = s.sphereCentre;
    v.sphereRadius = s.sphereRadius;
    return v;
}

}  // namespace mirage::test
