#pragma once
// Scenes built in code for the reference renderer's tests (analytic set-ups in the style of
// pbrt's tests). World frame glTF: metres, +Y up.
#include <cmath>
#include <string>

#include <glm/gtc/matrix_transform.hpp>
#include <opencv2/core.hpp>

#include "core/image/ImageIO.h"
#include "core/math/Pose.h"
#include "core/scene/Scene.h"
#include "render/raytrace/EmbreeDevice.h"
#include "render/raytrace/ReferenceRenderer.h"
#include "testscenes/RenderTestScenes.h"

namespace mirage::raytrace::test {

inline void fixWinding(Primitive& p, const glm::vec3& centre) {
    for (size_t i = 0; i < p.indices.size(); i += 3) {
        glm::vec3 a = p.positions[p.indices[i]], b = p.positions[p.indices[i + 1]],
                  c = p.positions[p.indices[i + 2]];
        glm::vec3 n = glm::cross(b - a, c - a);
        glm::vec3 ref = p.normals.empty() ? (a + b + c) / 3.0f - centre
                                          : p.normals[p.indices[i]] + p.normals[p.indices[i + 1]] +
                                                p.normals[p.indices[i + 2]];
        if (glm::dot(n, ref) < 0) std::swap(p.indices[i + 1], p.indices[i + 2]);
    }
}

// UV sphere centred at the origin (RenderTestScenes.h's generator: outward normals and winding).
inline Primitive spherePrimitive(float radius, int slices = 96, int stacks = 48) {
    return mirage::test::uvSpherePrimitive(glm::vec3(0.0f), radius, stacks, slices);
}

// Axis-aligned box [lo, hi] with flat outward normals.
inline Primitive boxPrimitive(glm::vec3 lo, glm::vec3 hi) {
    Primitive p;
    glm::vec3 c = 0.5f * (lo + hi);
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            glm::vec3 n(0.0f);
            n[axis] = side ? 1.0f : -1.0f;
            int u = (axis + 1) % 3, v = (axis + 2) % 3;
            auto base = uint32_t(p.positions.size());
            for (int k = 0; k < 4; ++k) {
                glm::vec3 q;
                q[axis] = side ? hi[axis] : lo[axis];
                q[u] = (k == 1 || k == 2) ? hi[u] : lo[u];
                q[v] = (k >= 2) ? hi[v] : lo[v];
                p.positions.push_back(q);
                p.normals.push_back(n);
                p.uv0.push_back({(k == 1 || k == 2) ? 1.0f : 0.0f, k >= 2 ? 1.0f : 0.0f});
            }
            p.indices.insert(p.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
        }
    fixWinding(p, c);
    return p;
}

// Square in the XZ plane (y = 0), side `size`, normal +Y.
inline Primitive floorPrimitive(float size) {
    Primitive p;
    float h = 0.5f * size;
    p.positions = {{-h, 0, -h}, {h, 0, -h}, {h, 0, h}, {-h, 0, h}};
    p.normals.assign(4, glm::vec3(0, 1, 0));
    p.uv0 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    p.indices = {0, 1, 2, 0, 2, 3};
    fixWinding(p, glm::vec3(0, -1, 0));
    return p;
}

inline Material lambert(glm::vec3 albedo, glm::vec3 emission = glm::vec3(0.0f)) {
    Material m;
    m.name = "lambert";
    m.baseColor = glm::vec4(albedo, 1.0f);
    m.metallic = 0.0f;
    m.roughness = 1.0f;
    m.ior = 1.0f;  // no specular layer: a pure Lambertian surface
    m.emissive = emission;
    return m;
}

inline Material glass(float ior, float roughness = 0.0f, glm::vec3 tint = glm::vec3(1.0f)) {
    Material m;
    m.name = "glass";
    m.baseColor = glm::vec4(tint, 1.0f);
    m.metallic = 0.0f;
    m.roughness = roughness;
    m.ior = ior;
    m.transmission = 1.0f;
    return m;
}

inline Material mirrorMaterial() {
    Material m;
    m.name = "mirror";
    m.baseColor = glm::vec4(1.0f);
    m.metallic = 1.0f;
    m.roughness = 0.0f;
    return m;
}

// Adds a mesh with one primitive and a node holding it; returns the node index.
inline int addObject(Scene& s, const std::string& name, Primitive prim, const Material& mat,
                     const glm::dmat4& world, Origin origin = Origin::Real) {
    s.materials.push_back(mat);
    prim.material = int(s.materials.size()) - 1;
    mirage::test::addMeshNode(s, name, std::move(prim), origin, world);
    return int(s.nodes.size()) - 1;
}

// The Embree device the reference renderer's tests share (2 threads: the machine's cores).
inline const EmbreeDevice& testDevice() {
    static EmbreeDevice d("threads=2");
    return d;
}

// A pinhole camera of w x h pixels, focal length f (pixels), principal point at the image centre,
// at `eye` looking at `target` (OpenCV camera axes in T_world_camera).
inline RenderCamera lookAtCamera(int w, int h, double f, glm::dvec3 eye, glm::dvec3 target,
                                 glm::dvec3 up = {0, 1, 0}) {
    RenderCamera c;
    c.intrinsics.width = w;
    c.intrinsics.height = h;
    c.intrinsics.fx = c.intrinsics.fy = f;
    c.intrinsics.cx = 0.5 * w - 0.5;
    c.intrinsics.cy = 0.5 * h - 0.5;
    // glm::lookAt builds a glTF-style view (camera looks down -Z): convert to OpenCV axes.
    c.T_world_camera =
        Pose::fromMatrix(glm::inverse(glm::lookAt(eye, target, up))) * kCvFromGltfCamera;
    return c;
}

inline int addLight(Scene& s, const std::string& name, Light light, const glm::dmat4& world,
                    Origin origin = Origin::Real) {
    light.name = name;
    s.lights.push_back(light);
    Node n;
    n.name = name;
    n.light = int(s.lights.size()) - 1;
    return mirage::test::addRootNode(s, std::move(n), world, origin);
}

// Camera node at `eye` looking at `target` (glTF camera: looks down its -Z, +Y up).
inline int addCameraNode(Scene& s, const std::string& name, glm::dvec3 eye, glm::dvec3 target,
                         float yfov, glm::dvec3 up = {0, 1, 0}) {
    CameraNodeInfo cam;
    cam.name = name;
    cam.yfov = yfov;
    s.cameras.push_back(cam);
    Node n;
    n.name = name;
    n.camera = int(s.cameras.size()) - 1;
    return mirage::test::addRootNode(s, std::move(n), glm::inverse(glm::lookAt(eye, target, up)),
                                     Origin::Real);
}

// Writes an environment image (linear RGB float) to `path` and makes it the scene's environment.
inline void setEnvironment(Scene& s, const std::filesystem::path& path, const cv::Mat& linearRgb,
                           float intensity = 1.0f) {
    writeLinearRgb(path, linearRgb);
    s.environment.kind = Environment::Kind::Equirectangular;
    s.environment.image = path;
    s.environment.intensity = intensity;
    s.environment.origin = Origin::Real;
}

inline cv::Mat constantImage(int w, int h, float value) {
    return cv::Mat(h, w, CV_32FC3, cv::Scalar::all(value));
}

inline glm::dmat4 translate(glm::dvec3 t) {
    return glm::translate(glm::dmat4(1.0), t);
}

// Mean of all pixels and channels.
inline double meanValue(const cv::Mat& img) {
    cv::Scalar m = cv::mean(img);
    return (m[0] + m[1] + m[2]) / 3.0;
}

inline bool allFinite(const cv::Mat& img) {
    return cv::checkRange(img, true, nullptr, -1e30, 1e30);
}

}  // namespace mirage::raytrace::test
