#pragma once
// Scenes for the specular-object tests (Knecht 2013 Fig. 2): a real table (checker-free
// diffuse plane), a glass (or mirror) sphere, a box the sphere REFLECTS (beside it, towards the
// camera), a box seen THROUGH it (behind it), a spot light, and a smooth sky environment. Each of
// the light, the specular object, the reflected and the refracted object is REAL or VIRTUAL.
// World = glTF (metres, +Y up); poses T_world_camera with OpenCV axes.
#include <cmath>
#include <filesystem>
#include <string>

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include "core/image/ImageIO.h"
#include "testscenes/RenderTestScenes.h"

namespace mirage::test {

inline int addGlass(Scene& s, float ior = 1.5f, glm::vec3 attenuationColor = glm::vec3(1.0f),
                    float attenuationDistance = INFINITY) {
    Material m;
    m.name = "glass" + std::to_string(s.materials.size());
    m.baseColor = glm::vec4(1.0f);
    m.metallic = 0.0f;
    m.roughness = 0.0f;
    m.transmission = 1.0f;
    m.ior = ior;
    m.attenuationColor = attenuationColor;
    m.attenuationDistance = attenuationDistance;
    s.materials.push_back(m);
    return int(s.materials.size()) - 1;
}

inline int addMirror(Scene& s, glm::vec3 colour = glm::vec3(0.95f)) {
    Material m;
    m.name = "mirror" + std::to_string(s.materials.size());
    m.baseColor = glm::vec4(colour, 1.0f);
    m.metallic = 1.0f;
    m.roughness = 0.0f;
    s.materials.push_back(m);
    return int(s.materials.size()) - 1;
}

// A smooth sky: linear radiance from 0.15 at the nadir to 0.6 (bluish) at the zenith, written as
// a small equirectangular .pfm under `dir`, and set as the scene's (real) environment.
inline void addSkyEnvironment(Scene& s, const std::filesystem::path& dir) {
    cv::Mat img(32, 64, CV_32FC3);
    for (int y = 0; y < img.rows; ++y)
        for (int x = 0; x < img.cols; ++x) {
            const float up = 1.0f - (y + 0.5f) / img.rows;  // 1 at the top row
            const float side = 0.5f + 0.5f * std::sin(2.0f * float(M_PI) * (x + 0.5f) / img.cols);
            img.at<cv::Vec3f>(y, x) =
                cv::Vec3f(0.15f + 0.3f * up + 0.1f * side, 0.15f + 0.4f * up, 0.15f + 0.5f * up);
        }
    std::filesystem::create_directories(dir);
    const std::filesystem::path path = dir / "sky.pfm";
    writeLinearRgb(path, img);
    s.environment.kind = Environment::Kind::Equirectangular;
    s.environment.image = path;
    s.environment.intensity = 1.0f;
    s.environment.origin = Origin::Real;
}

struct SpecularCase {
    bool lightReal = true, objectReal = false, reflectedReal = true, refractedReal = true;
    std::string name() const {
        auto rv = [](bool r) { return r ? "R" : "V"; };
        return std::string("light") + rv(lightReal) + "_object" + rv(objectReal) + "_refl" +
               rv(reflectedReal) + "_refr" + rv(refractedReal);
    }
};

struct SpecularScene {
    Scene scene;
    CameraIntrinsics cam = smallCamera(96, 72, 90.0);
    Pose pose = lookAtPose({0.0, 0.55, 1.1}, {0.0, 0.15, 0.0});
    glm::vec3 sphereCentre{0.0f, 0.2f, 0.0f};
    float sphereRadius = 0.2f;
};

enum class SpecularKind { Glass, Mirror };

inline SpecularScene makeSpecularScene(const SpecularCase& c, const std::filesystem::path& envDir,
                                       SpecularKind kind = SpecularKind::Glass, float ior = 1.5f) {
    SpecularScene s;
    const int table = addMaterial(s.scene, glm::vec3(0.6f, 0.55f, 0.5f));
    const int red = addMaterial(s.scene, glm::vec3(0.8f, 0.15f, 0.1f));
    const int green = addMaterial(s.scene, glm::vec3(0.15f, 0.7f, 0.2f));
    const int spec = kind == SpecularKind::Glass ? addGlass(s.scene, ior) : addMirror(s.scene);
    addFloor(s.scene, "table", 0.0f, 3.0f, table, Origin::Real);
    addUvSphere(s.scene, "specular sphere", s.sphereCentre, s.sphereRadius, spec,
                c.objectReal ? Origin::Real : Origin::Virtual);
    // Reflected: a red box beside the sphere, towards the camera (seen in the sphere's left).
    addBox(s.scene, "reflected box", {-0.55f, 0.0f, 0.05f}, {-0.35f, 0.3f, 0.35f}, red,
           c.reflectedReal ? Origin::Real : Origin::Virtual);
    // Refracted: a green box behind the sphere (seen through it).
    addBox(s.scene, "refracted box", {-0.1f, 0.0f, -0.6f}, {0.2f, 0.25f, -0.4f}, green,
           c.refractedReal ? Origin::Real : Origin::Virtual);
    const glm::vec3 lightPos(0.6f, 1.4f, 0.5f);
    addLight(s.scene, Light::Type::Spot, lightPos, glm::normalize(glm::vec3(0.0f) - lightPos), 3.0f,
             c.lightReal ? Origin::Real : Origin::Virtual, 1.0f, 0.8f);
    addSkyEnvironment(s.scene, envDir);
    return s;
}

// Pixels whose camera ray meets the sphere (pinhole without distortion), CV_8U 255 / 0;
// `shrink` px less radius keeps silhouette pixels (mixed in the reference) out.
inline cv::Mat sphereMask(const SpecularScene& s, double shrink = 1.0) {
    cv::Mat m(s.cam.height, s.cam.width, CV_8U, cv::Scalar(0));
    const glm::dvec3 c = s.pose.inverse() * glm::dvec3(s.sphereCentre);
    const double d = glm::length(c);
    const double angR = std::asin(std::min(1.0, double(s.sphereRadius) / d));
    for (int y = 0; y < m.rows; ++y)
        for (int x = 0; x < m.cols; ++x) {
            const glm::dvec3 ray = glm::normalize(
                glm::dvec3((x - s.cam.cx) / s.cam.fx, (y - s.cam.cy) / s.cam.fy, 1.0));
            const double ang = std::acos(std::clamp(glm::dot(ray, c / d), -1.0, 1.0));
            if (ang < angR - shrink / s.cam.fx) m.at<uint8_t>(y, x) = 255;
        }
    return m;
}

}  // namespace mirage::test
