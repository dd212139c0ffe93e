#pragma once
// Where the user put the scene's virtual objects in a live session (docs/live.md, "Placing the
// virtual objects"): a move within the board's plane, a turn about its normal and a uniform
// scale, about the virtual objects' centre on that plane. Real proxies never move (they model
// the real world). Saved next to the scene as <scene>.placement.json and applied by `mirage
// live` and `mirage replay` alike, so a replay of a live recording composites the objects where
// they were.
#include <filesystem>
#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"
#include "core/scene/Scene.h"

namespace mirage {

// The board's plane in the world: a point on it, its unit normal (out of the page, towards the
// camera side) and a unit in-plane axis (the board's +X); metres, world = glTF frame.
struct PlacementPlane {
    glm::dvec3 point{0.0};
    glm::dvec3 normal{0.0, 1.0, 0.0};
    glm::dvec3 axisU{1.0, 0.0, 0.0};
};

struct ScenePlacement {
    double moveU = 0, moveV = 0;  // metres along axisU and normal x axisU
    double turnDeg = 0;           // about the normal, counter-clockwise seen from its side
    double scale = 1;             // uniform, > 0

    bool isIdentity() const { return moveU == 0 && moveV == 0 && turnDeg == 0 && scale == 1; }
    bool operator==(const ScenePlacement&) const = default;
};

// The world-from-world transform of the placement: about `pivot` projected onto the plane.
glm::dmat4 placementMatrix(const ScenePlacement& p, const PlacementPlane& plane,
                           const glm::dvec3& pivot);
// The centre of the virtual mesh instances' origins (world), the pivot of a placement.
glm::dvec3 virtualCentre(const Scene& scene);
// Applies the placement to every virtual node (the top virtual node of each virtual subtree is
// moved; its descendants follow). Returns the number of subtrees moved.
int applyPlacement(Scene& scene, const ScenePlacement& p, const PlacementPlane& plane);

// Where the camera ray through `pixel` (camera image pixels, centre of the top-left pixel at
// (0, 0)) meets the plane, in the world; nullopt when the ray misses it (parallel, or the plane
// is behind the camera). `T_world_camera` in OpenCV camera axes. For dragging objects with the
// mouse.
std::optional<glm::dvec3> pixelOnPlane(const CameraIntrinsics& camera, const Pose& T_world_camera,
                                       const glm::dvec2& pixel, const PlacementPlane& plane);
// The in-plane move (along axisU, and along normal x axisU) from world point a to world point b.
glm::dvec2 inPlaneMove(const glm::dvec3& a, const glm::dvec3& b, const PlacementPlane& plane);

// <scene file>.placement.json
std::filesystem::path placementPath(const std::filesystem::path& scene);
// nullopt if the file does not exist; throws FileError naming the field when it is invalid.
std::optional<ScenePlacement> loadPlacement(const std::filesystem::path& path);
void savePlacement(const std::filesystem::path& path, const ScenePlacement& p);  // atomically

}  // namespace mirage
