#pragma once
// Scenes for the rough-surface tests (fuzzy reflections, rough refraction): a virtual object on a
// real table (3 m) with real boxes behind it, a real spot light and a smooth sky; its differential
// reference from the Embree renderer (GGX conductors and dielectrics); the real-time frame.
// World = glTF (metres, +Y up); poses T_world_camera with OpenCV axes.
#include <filesystem>
#include <string>

#include <glm/glm.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "render/Renderer.h"
#include "render/raytrace/DifferentialRendering.h"
#include "render/raytrace/EmbreeDevice.h"
#include "testscenes/ReferenceFrame.h"
#include "testscenes/SpecularTestScenes.h"

namespace mirage::test {

struct RoughTestScene {
    Scene scene;
    CameraIntrinsics cam = smallCamera(128, 96, 120.0);
    Pose pose = lookAtPose({0.0, 0.5, 0.9}, {0.0, 0.05, -0.1});
    int material = -1;  // the rough object's
};

// A virtual glass slab (50 x 30 x 6 cm, IOR 1.5, centred on z = 0, standing on the table) in
// front of a real red and a real green box: what is seen through it has sharp edges for the
// roughness to blur.
inline RoughTestScene makeRoughSlab(float roughness, const std::filesystem::path& envDir) {
    RoughTestScene s;
    s.pose = lookAtPose({0.0, 0.25, 0.8}, {0.0, 0.12, -0.1});
    const int table = addMaterial(s.scene, glm::vec3(0.6f, 0.55f, 0.5f));
    const int red = addMaterial(s.scene, glm::vec3(0.8f, 0.15f, 0.1f));
    const int green = addMaterial(s.scene, glm::vec3(0.15f, 0.7f, 0.2f));
    s.material = addGlass(s.scene);
    s.scene.materials[size_t(s.material)].roughness = roughness;
    addFloor(s.scene, "table", 0.0f, 3.0f, table, Origin::Real);
    addBox(s.scene, "slab", {-0.25f, 0.0f, -0.03f}, {0.25f, 0.3f, 0.03f}, s.material,
           Origin::Virtual);
    addBox(s.scene, "red box", {-0.12f, 0.0f, -0.35f}, {0.04f, 0.2f, -0.2f}, red, Origin::Real);
    addBox(s.scene, "green box", {0.04f, 0.0f, -0.4f}, {0.16f, 0.12f, -0.28f}, green, Origin::Real);
    const glm::vec3 lightPos(0.6f, 1.4f, 0.5f);
    addLight(s.scene, Light::Type::Spot, lightPos,
             glm::normalize(glm::vec3(0.0f, 0.0f, -0.3f) - lightPos), 3.0f, Origin::Real, 1.0f,
             0.8f);
    addSkyEnvironment(s.scene, envDir);
    return s;
}

// Pixels whose camera ray meets the slab's front face (z = 0.03) with x in (xLo, xHi), 1 px in
// from the outline (mixed pixels).
inline cv::Mat slabFrontMask(const RoughTestScene& s, double xLo = -0.25, double xHi = 0.25) {
    cv::Mat m(s.cam.height, s.cam.width, CV_8U, cv::Scalar(0));
    const glm::dvec3 eye = s.pose * glm::dvec3(0.0);
    for (int y = 0; y < m.rows; ++y)
        for (int x = 0; x < m.cols; ++x) {
            const glm::dvec3 dirCam((x - s.cam.cx) / s.cam.fx, (y - s.cam.cy) / s.cam.fy, 1.0);
            const glm::dvec3 d = s.pose * dirCam - eye;
            if (d.z >= 0) continue;
            const glm::dvec3 p = eye + ((0.03 - eye.z) / d.z) * d;
            if (p.x > xLo && p.x < xHi && p.y > 0.0 && p.y < 0.3) m.at<uint8_t>(y, x) = 255;
        }
    cv::erode(m, m, cv::Mat::ones(3, 3, CV_8U));
    return m;
}

struct RoughReference {
    cv::Mat footage, refSrgb;  // the reference's real-only render and its composite, sRGB8 BGR
};

// The Embree differential reference (caustics off: the rough object's light on the table is not
// judged by these tests).
inline RoughReference roughReference(const RoughTestScene& s, int spp = 64, int seed = 5) {
    const ReferenceFrame f =
        renderReferenceFrame(s.scene, s.cam, s.pose, spp, uint64_t(seed), false);
    return {f.footage, f.composite};
}

inline render::RendererOptions roughSingleFrame() {
    render::RendererOptions o;
    o.temporalBlend = 0.0f;
    o.caustic.enabled = false;
    return o;
}

struct RoughFrame {
    cv::Mat srgb, linear;
    render::FrameReport report;
};

inline RoughFrame renderRough(const RoughTestScene& s, const cv::Mat& footage,
                              const render::RendererOptions& opt = roughSingleFrame()) {
    render::Renderer r(s.scene, s.cam, opt);
    RoughFrame f;
    f.report = r.render({s.pose, footage, true});
    f.srgb = r.compositeSrgb();
    f.linear = r.compositeLinear();
    EXPECT_TRUE(cv::checkRange(f.linear)) << "NaN/Inf in the composite";
    return f;
}

}  // namespace mirage::test
