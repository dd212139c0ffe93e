#pragma once
// A printable planar grid board (`mirage board`) and how it sits in the world.
//
// Page layout (page metres, origin at the top-left of the page, +x right, +y down):
//   margin | tag | gap | tag | ... | margin, rows likewise, then a footer holding a scale bar and a
//   caption. Tag (row r, column c), counted from the top-left, has id firstId + r*cols + c; its
//   detection corners (outer corners of the black border) span tagSize metres.
//
// In the world (default T_world_sheet = tableSheetPose()): the page lies on the world XZ plane
// (y = 0) facing +Y (up), its centre at the world origin, page +x along world +X and page +y (down
// the page) along world +Z. So a viewer standing at +Z looking towards -Z reads the page upright,
// and every tag's frame has +X = world +X, +Y = world +Z, +Z = world -Y (into the table).
#include <string>

#include "core/NumberRange.h"
#include "core/math/Pose.h"
#include "tracking/Board.h"

namespace mirage::tracking {

// What a printable board may measure (metres; a sheet beyond a metre or a grid beyond 100 x 100
// tags is no longer a printout). makeBoard() and `mirage board`'s options check the same ranges.
inline constexpr NumberRange kBoardTagSizeM{0, 1, true, false};
inline constexpr NumberRange kBoardGapM{0, 1};
inline constexpr NumberRange kBoardMarginM{0, 1};
inline constexpr int kBoardMaxTagsPerSide = 100;

struct BoardLayout {
    int rows = 4, cols = 6;
    double tagSize = 0.032;  // metres between detection corners
    double gap = 0.008;      // metres between neighbouring tags' detection corners
    int firstId = 0;
    double margin = 0.01;  // metres of white page around the grid
    std::string family = "tag36h11";
    Pose T_world_sheet = tableSheetPose();

    // The page lying on the world XZ plane facing +Y, centred at the origin (see above).
    static Pose tableSheetPose();

    // The board: tags with their world poses and the sheet (page size, scale bar, caption).
    // Throws mirage::Error on a layout that cannot be printed: rows/cols outside
    // [1, kBoardMaxTagsPerSide], sizes outside the ranges above (NaN, infinite), ids beyond the
    // family, or gap/margin narrower than the tags' quiet zone.
    Board makeBoard() const;
};

}  // namespace mirage::tracking
