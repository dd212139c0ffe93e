#pragma once
// Scenes built in code for the real-time renderer tests (small, analytic). World = glTF frame
// (metres, +Y up); camera poses are T_world_camera with OpenCV axes.
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include <glm/glm.hpp>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"
#include "core/scene/Scene.h"
#include "testscenes/LookAt.h"

namespace mirage::test {

inline int addMaterial(Scene& s, glm::vec3 albedo, float roughness = 1.0f, float metallic = 0.0f) {
    Material m;
    m.name = "m" + std::to_string(s.materials.size());
    m.baseColor = glm::vec4(albedo, 1.0f);
    m.roughness = roughness;
    m.metallic = metallic;
    s.materials.push_back(m);
    return int(s.materials.size()) - 1;
}

// Appends `n` to the scene as a root node at `world` (local = world) and returns its index.
inline int addRootNode(Scene& s, Node n, const glm::dmat4& world, Origin origin) {
    n.local = n.world = world;
    n.origin = origin;
    s.nodes.push_back(std::move(n));
    s.roots.push_back(int(s.nodes.size()) - 1);
    return int(s.nodes.size()) - 1;
}

// Appends the quad a-b-c-d (counter-clockwise seen from the side `normal` points to) as two
// triangles with a flat normal.
inline void appendQuad(Primitive& p, glm::vec3 normal, glm::vec3 a, glm::vec3 b, glm::vec3 c,
                       glm::vec3 d) {
    const uint32_t base = uint32_t(p.positions.size());
    p.positions.insert(p.positions.end(), {a, b, c, d});
    p.normals.insert(p.normals.end(), {normal, normal, normal, normal});
    p.indices.insert(p.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

inline void addMeshNode(Scene& s, const std::string& name, Primitive prim, Origin origin,
                        const glm::dmat4& world = glm::dmat4(1.0)) {
    Mesh mesh;
    mesh.name = name;
    mesh.primitives.push_back(std::move(prim));
    s.meshes.push_back(std::move(mesh));
    Node n;
    n.name = name;
    n.mesh = int(s.meshes.size()) - 1;
    addRootNode(s, std::move(n), world, origin);
}

// UV sphere (rings x segments quads; the pole rows are single triangles) with outward normals,
// uv and outward winding: the reference renderer takes a transmissive surface's outside from the
// triangle winding, so an inward-wound glass sphere would be rendered as an air bubble in glass.
// The one sphere generator of the render tests (the reference renderer's tests use it too).
inline Primitive uvSpherePrimitive(glm::vec3 c, float r, int rings = 32, int segments = 48) {
    Primitive p;
    for (int i = 0; i <= rings; ++i) {
        const float th = float(M_PI) * float(i) / float(rings);
        for (int j = 0; j <= segments; ++j) {
            const float ph = 2.0f * float(M_PI) * float(j) / float(segments);
            glm::vec3 n(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
            p.positions.push_back(c + r * n);
            p.normals.push_back(n);
            p.uv0.push_back({float(j) / float(segments), float(i) / float(rings)});
        }
    }
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            const uint32_t a = uint32_t(i * (segments + 1) + j), b = a + uint32_t(segments + 1);
            if (i > 0) p.indices.insert(p.indices.end(), {a, a + 1, b});  // not at the north pole
            if (i < rings - 1) p.indices.insert(p.indices.end(), {a + 1, b + 1, b});  // nor south
        }
    return p;
}

inline void addUvSphere(Scene& s, const std::string& name, glm::vec3 c, float r, int material,
                        Origin origin, int rings = 32, int segments = 48) {
    Primitive p = uvSpherePrimitive(c, r, rings, segments);
    p.material = material;
    addMeshNode(s, name, std::move(p), origin);
}

// Horizontal square at height y, normal +Y, side `size` centred at (cx, y, cz).
inline void addFloor(Scene& s, const std::string& name, float y, float size, int material,
                     Origin origin, float cx = 0.0f, float cz = 0.0f) {
    Primitive p;
    const float h = size * 0.5f;
    p.positions = {
        {cx - h, y, cz - h}, {cx + h, y, cz - h}, {cx + h, y, cz + h}, {cx - h, y, cz + h}};
    p.normals.assign(4, glm::vec3(0, 1, 0));
    p.indices = {0, 2, 1, 0, 3, 2};
    p.material = material;
    addMeshNode(s, name, std::move(p), origin);
}

// Axis-aligned box with outward normals (24 vertices, flat faces).
inline void addBox(Scene& s, const std::string& name, glm::vec3 lo, glm::vec3 hi, int material,
                   Origin origin) {
    Primitive p;
    auto face = [&](glm::vec3 n, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
        appendQuad(p, n, a, b, c, d);
    };
    const glm::vec3 L = lo, H = hi;
    face({0, 1, 0}, {L.x, H.y, L.z}, {L.x, H.y, H.z}, {H.x, H.y, H.z}, {H.x, H.y, L.z});
    face({0, -1, 0}, {L.x, L.y, L.z}, {H.x, L.y, L.z}, {H.x, L.y, H.z}, {L.x, L.y, H.z});
    face({1, 0, 0}, {H.x, L.y, L.z}, {H.x, H.y, L.z}, {H.x, H.y, H.z}, {H.x, L.y, H.z});
    face({-1, 0, 0}, {L.x, L.y, L.z}, {L.x, L.y, H.z}, {L.x, H.y, H.z}, {L.x, H.y, L.z});
    face({0, 0, 1}, {L.x, L.y, H.z}, {H.x, L.y, H.z}, {H.x, H.y, H.z}, {L.x, H.y, H.z});
    face({0, 0, -1}, {L.x, L.y, L.z}, {L.x, H.y, L.z}, {H.x, H.y, L.z}, {H.x, L.y, L.z});
    p.material = material;
    addMeshNode(s, name, std::move(p), origin);
}

// A light node at `pos` shining along `dir` (the node's -Z axis is turned onto dir).
inline void addLight(Scene& s, Light::Type type, glm::vec3 pos, glm::vec3 dir, float intensity,
                     Origin origin, float outer = 0.6f, float inner = 0.5f,
                     glm::vec3 color = glm::vec3(1.0f)) {
    Light l;
    l.name = "light" + std::to_string(s.lights.size());
    l.type = type;
    l.intensity = intensity;
    l.color = color;
    l.outerConeAngle = outer;
    l.innerConeAngle = inner;
    s.lights.push_back(l);
    const glm::dvec3 z = -glm::normalize(glm::dvec3(dir));  // node +Z = -dir
    const glm::dvec3 up = std::abs(z.y) < 0.99 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    const glm::dvec3 x = glm::normalize(glm::cross(up, z));
    const glm::dvec3 y = glm::cross(z, x);
    glm::dmat4 m(1.0);
    m[0] = glm::dvec4(x, 0);
    m[1] = glm::dvec4(y, 0);
    m[2] = glm::dvec4(z, 0);
    m[3] = glm::dvec4(glm::dvec3(pos), 1);
    Node n;
    n.name = l.name;
    n.light = int(s.lights.size()) - 1;
    addRootNode(s, std::move(n), m, origin);
}

// T_world_camera of an OpenCV camera at `eye` looking at `target` (+Y world up).
inline Pose lookAtPose(glm::dvec3 eye, glm::dvec3 target) {
    return lookAt(eye, target, glm::dvec3(0, 1, 0));
}

inline CameraIntrinsics smallCamera(int w = 160, int h = 120, double f = 130.0) {
    CameraIntrinsics c;
    c.width = w;
    c.height = h;
    c.fx = c.fy = f;
    c.cx = (w - 1) * 0.5;
    c.cy = (h - 1) * 0.5;
    return c;
}

// A real table (4 m) under a real spot light, a virtual box (40 cm) on it, and the pose that
// overlooks them: the exposure-matching and motion-blur tests' scene.
inline Scene spotLitTableWithVirtualBox() {
    Scene s;
    const int table = addMaterial(s, glm::vec3(0.7f));
    const int boxMat = addMaterial(s, glm::vec3(0.8f, 0.3f, 0.2f));
    addFloor(s, "table", 0.0f, 4.0f, table, Origin::Real);
    addBox(s, "virtual box", {-0.2f, 0.0f, -0.2f}, {0.2f, 0.4f, 0.2f}, boxMat, Origin::Virtual);
    const glm::vec3 lightPos{1.2f, 2.0f, 0.0f};
    const glm::vec3 axis = glm::normalize(glm::vec3(-0.6f, 0.0f, 0.0f) - lightPos);
    addLight(s, Light::Type::Spot, lightPos, axis, 8.0f, Origin::Real, 1.0f, 0.9f);
    return s;
}
inline Pose spotLitTableOverview() {
    return lookAtPose({0, 2.5, 2.5}, {0, 0, 0});
}

// World point on the plane y = 0 seen by pixel (x, y) of a pinhole camera, if any.
inline std::optional<glm::dvec3> floorHit(const CameraIntrinsics& cam, const Pose& T_world_camera,
                                          int x, int y) {
    auto ray = cam.unproject(glm::dvec2(x, y));
    if (!ray) return std::nullopt;
    const glm::dvec3 d = T_world_camera.rotationMatrix() * *ray;
    const glm::dvec3 o = T_world_camera.translation;
    if (d.y >= -1e-9) return std::nullopt;
    return o + d * (-o.y / d.y);
}

// Does the segment a -> b pass through the axis-aligned box [lo, hi] (slab test)?
inline bool segmentHitsBox(glm::dvec3 a, glm::dvec3 b, glm::dvec3 lo, glm::dvec3 hi) {
    const glm::dvec3 d = b - a;
    double t0 = 0, t1 = 1;
    for (int i = 0; i < 3; ++i) {
        if (std::abs(d[i]) < 1e-12) {
            if (a[i] < lo[i] || a[i] > hi[i]) return false;
            continue;
        }
        const double u = (lo[i] - a[i]) / d[i], v = (hi[i] - a[i]) / d[i];
        t0 = std::max(t0, std::min(u, v));
        t1 = std::min(t1, std::max(u, v));
    }
    return t0 <= t1;
}

}  // namespace mirage::test
