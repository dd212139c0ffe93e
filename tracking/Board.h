#pragma once
// A tag board: where each AprilTag sits in the world (docs/tracking.md, "Board file").
//
// Tag frame (libapriltag's, as in apriltag_pose.c): origin at the tag centre, +X to the right of
// the printed tag, +Y down the printed tag, +Z into the tag (away from a viewer who reads it).
// The detection corners, in the order libapriltag reports them (counter-clockwise in the image),
// are in the tag frame, for edge length s (metres, between detection corners = outer corners of
// the black border for tag36h11):
//     corner 0 = (-s/2, +s/2, 0)  bottom-left of the printed tag
//     corner 1 = (+s/2, +s/2, 0)  bottom-right
//     corner 2 = (+s/2, -s/2, 0)  top-right
//     corner 3 = (-s/2, -s/2, 0)  top-left
// Each tag's pose in the world is T_world_tag (maps tag-frame points to the world; world = the
// scene's glTF frame, metres, +Y up). Boards may be non-planar (tags on several faces).
//
// A planar printed board also has a sheet: the printed page as a rectangle in the world, used to
// texture a plane in synthetic scenes and to print. Sheet frame = tag frame conventions: origin at
// the sheet centre, +X right, +Y down the printed page, +Z into the page.
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/math/Pose.h"

namespace mirage::tracking {

struct BoardTag {
    int id = 0;
    double size = 0;  // metres between detection corners
    Pose T_world_tag;

    // Detection corners in the tag frame / in the world, libapriltag's order (see above).
    static std::array<glm::dvec3, 4> cornersInTag(double size);
    std::array<glm::dvec3, 4> cornersInWorld() const;
};

struct BoardSheet {
    double width = 0, height = 0;  // metres, the whole printed page (margins, scale bar included)
    Pose T_world_sheet;            // sheet frame (centre, +X right, +Y down the page) -> world
    // Scale bar drawn on the page: top-left corner in page metres (origin top-left of the page,
    // +x right, +y down), its length (metres) and thickness (metres). length 0 = none.
    glm::dvec2 scaleBarTopLeft{0.0};
    double scaleBarLength = 0, scaleBarThickness = 0;
    std::string caption;  // printed below the scale bar
};

class Board {
public:
    std::string family = "tag36h11";
    std::vector<BoardTag> tags;
    std::optional<BoardSheet> sheet;

    const BoardTag* find(int id) const;
    // True if every tag lies in one plane (corners within 1e-6 m of a common plane).
    bool isPlanar() const;

    // Reads a board file (JSON, docs/tracking.md). Throws mirage::FileError naming the file and
    // the field on anything missing or invalid (duplicate ids, non-positive sizes, ids outside
    // the family, non-unit quaternions beyond 1e-3, ...).
    static Board load(const std::filesystem::path& path);
    // Parses board JSON text; `source` names it in error messages.
    static Board parse(const std::string& jsonText, const std::string& source);
    // Writes atomically (temporary file + rename).
    void save(const std::filesystem::path& path) const;
    std::string toJson() const;
};

}  // namespace mirage::tracking
