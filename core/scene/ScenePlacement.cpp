#include "core/scene/ScenePlacement.h"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "core/session/AtomicFile.h"

namespace mirage {

glm::dmat4 placementMatrix(const ScenePlacement& p, const PlacementPlane& plane,
                           const glm::dvec3& pivot) {
    const glm::dvec3 n = glm::normalize(plane.normal);
    const glm::dvec3 u = glm::normalize(plane.axisU - glm::dot(plane.axisU, n) * n);
    const glm::dvec3 v = glm::cross(n, u);
    // The pivot on the plane, so that turning and scaling keep the objects on the board.
    const glm::dvec3 c = pivot - glm::dot(pivot - plane.point, n) * n;
    glm::dmat4 m(1.0);
    m = glm::translate(m, c + p.moveU * u + p.moveV * v);
    m = glm::rotate(m, glm::radians(p.turnDeg), n);
    m = glm::scale(m, glm::dvec3(p.scale));
    m = glm::translate(m, -c);
    return m;
}

std::optional<glm::dvec3> pixelOnPlane(const CameraIntrinsics& camera, const Pose& T_world_camera,
                                       const glm::dvec2& pixel, const PlacementPlane& plane) {
    const std::optional<glm::dvec3> ray = camera.unproject(pixel);
    if (!ray) return std::nullopt;
    const glm::dvec3 o = T_world_camera.translation;
    const glm::dvec3 d = T_world_camera.rotation * *ray;
    const glm::dvec3 n = glm::normalize(plane.normal);
    const double denom = glm::dot(d, n);
    if (std::abs(denom) < 1e-9) return std::nullopt;
    const double t = glm::dot(plane.point - o, n) / denom;
    if (!(t > 0)) return std::nullopt;
    return o + t * d;
}

glm::dvec2 inPlaneMove(const glm::dvec3& a, const glm::dvec3& b, const PlacementPlane& plane) {
    const glm::dvec3 n = glm::normalize(plane.normal);
    const glm::dvec3 u = glm::normalize(plane.axisU - glm::dot(plane.axisU, n) * n);
    const glm::dvec3 v = glm::cross(n, u);
    return {glm::dot(b - a, u), glm::dot(b - a, v)};
}

glm::dvec3 virtualCentre(const Scene& scene) {
    glm::dvec3 sum(0.0);
    int n = 0;
    for (const MeshInstance& mi : scene.meshInstances())
        if (mi.origin == Origin::Virtual) {
            sum += glm::dvec3(mi.world[3]);
            ++n;
        }
    return n ? sum / double(n) : glm::dvec3(0.0);
}

namespace {
void recomputeWorld(Scene& s, int node, const glm::dmat4& parentWorld) {
    Node& nd = s.nodes[size_t(node)];
    nd.world = parentWorld * nd.local;
    for (int c : nd.children) recomputeWorld(s, c, nd.world);
}
}  // namespace

int applyPlacement(Scene& scene, const ScenePlacement& p, const PlacementPlane& plane) {
    if (!(p.scale > 0) || !std::isfinite(p.scale) || !std::isfinite(p.moveU) ||
        !std::isfinite(p.moveV) || !std::isfinite(p.turnDeg))
        throw Error("placement: scale must be > 0 and every number finite");
    if (p.isIdentity()) return 0;
    const glm::dmat4 m = placementMatrix(p, plane, virtualCentre(scene));
    int moved = 0;
    for (size_t i = 0; i < scene.nodes.size(); ++i) {
        Node& nd = scene.nodes[i];
        if (nd.origin != Origin::Virtual) continue;
        const bool top = nd.parent < 0 || scene.nodes[size_t(nd.parent)].origin != Origin::Virtual;
        if (!top) continue;
        const glm::dmat4 parentWorld =
            nd.parent < 0 ? glm::dmat4(1.0) : scene.nodes[size_t(nd.parent)].world;
        // New world = m * old world; the local matrix keeps the parent relation.
        nd.local = glm::inverse(parentWorld) * m * nd.world;
        recomputeWorld(scene, int(i), parentWorld);
        ++moved;
    }
    return moved;
}

std::filesystem::path placementPath(const std::filesystem::path& scene) {
    return std::filesystem::path(scene.string() + ".placement.json");
}

std::optional<ScenePlacement> loadPlacement(const std::filesystem::path& path) {
    if (!std::filesystem::exists(path)) return std::nullopt;
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(readFileBytes(path));
    } catch (const nlohmann::json::exception& e) {
        throw FileError(path.string(), std::string("not valid JSON: ") + e.what());
    }
    if (!j.is_object() || j.value("format", "") != "mirage-placement")
        throw FileError(path.string(), "field 'format': expected \"mirage-placement\"");
    if (j.value("version", 0) != 1)
        throw FileError(path.string(), "field 'version': this mirage reads version 1");
    ScenePlacement p;
    auto num = [&](const char* key, double& out) {
        if (!j.contains(key)) return;
        if (!j[key].is_number() || !std::isfinite(j[key].get<double>()))
            throw FileError(path.string(), std::string("field '") + key + "': must be a number");
        out = j[key].get<double>();
    };
    num("move_u_m", p.moveU);
    num("move_v_m", p.moveV);
    num("turn_deg", p.turnDeg);
    num("scale", p.scale);
    if (!(p.scale > 0)) throw FileError(path.string(), "field 'scale': must be > 0");
    return p;
}

void savePlacement(const std::filesystem::path& path, const ScenePlacement& p) {
    nlohmann::json j = {{"format", "mirage-placement"}, {"version", 1},
                        {"move_u_m", p.moveU},          {"move_v_m", p.moveV},
                        {"turn_deg", p.turnDeg},        {"scale", p.scale}};
    writeFileAtomically(path, j.dump(2) + "\n");
}

}  // namespace mirage
