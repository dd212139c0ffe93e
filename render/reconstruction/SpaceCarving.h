#pragma once
// Objects on the table from their silhouettes against the known plane (docs/reconstruction.md,
// "Space carving"). Real objects often have plain faces where photo-consistency stereo finds no
// depth; but the table's plane and every camera pose are known, so each pixel can be asked
// whether it shows the table where its ray meets the plane:
//  1. the plane's appearance: every cell of the plane (cellM) is projected into every frame.
//     References: the chromaticity and brightness of the board's paper and of the table around
//     the board (plain medians). A cell is the table's when enough frames see the table's
//     chromaticity there; its colour is the median of those samples (a diffuse table looks the
//     same from every view, spot pools and shadows included; a cell hidden behind an object in
//     most frames still gets its colour from the few that see it). The table is the region of
//     such cells holding most of the board; inside its convex hull the other cells are covered
//     (footprints: every ray ending there passes through an object); outside it, off the table;
//  2. each pixel is classed: its ray meets the plane in a table cell and its colour matches the
//     cell's (the table is seen: nothing stands on that ray above the plane), or it does not
//     (something above the plane). A ray meeting a covered cell sees the table when the pixel
//     has the table's chromaticity; a ray off the table sees past the objects when the pixel
//     has the colour the frames commonly see through that cell (the floor), else says nothing;
//  3. a voxel column over the plane is carved bottom-up: a voxel is empty when at least
//     minPlaneVotes frames see the table through it, occupied when at least minObjectVotes
//     frames (and minObjectShare of those deciding) see something above the plane there. A
//     single frame never carves (a mistracked frame, noise), and nothing is made where the
//     frames only see off the table.
//  4. columns whose top fewer than minObjectVotes frames see (the ray to the camera passes under
//     another column's top) are dropped: the hull's slope behind an object seen from one side.
// The result is a height field over the plane (the top of each column's occupied run from the
// table up): the visual hull against the table, exact for boxes and cylinders seen from all
// sides, grown behind objects on their unseen sides. Units: metres, plane frame
// (BoardPlane::toPlane); colours linear (sRGB primaries).
#include <vector>

#include <opencv2/core.hpp>

#include "render/reconstruction/Footage.h"

namespace mirage::reconstruction {

struct CarvingOptions {
    bool enabled = true;
    double voxelM = 0.004;        // column cell and voxel height
    double regionHalfM = 0.7;     // plane region searched around the board (metres, each way)
    double maxHeightM = 0.3;      // columns end here
    double startHeightM = 0.006;  // the first voxel's centre (contact shadows lie lower)
    int maxFrames = 48;           // frames used at most (spread evenly over the footage)
    // A pixel shows the table when |colour - table's colour| <= colourFloor + colourTolerance *
    // |table's colour| (linear RGB, Euclidean; after a blur of blurPixels at 320 px width).
    double colourTolerance = 0.2;
    double colourFloor = 0.01;
    double blurPixels = 1.0;
    // A cell is table-coloured when its chromaticity (r, g over r+g+b) is within this of the
    // table's (the median of the cells around the board) and it is not darker than
    // minTableBrightness of the table's median brightness. On the board: within boardChroma of
    // the paper's, or dark (the tags' ink).
    double tableChroma = 0.04;
    double boardChroma = 0.06;
    double minTableBrightness = 0.12;
    int minFramesPerCell = 3;  // cells seen by fewer frames are unknown
    // A cell is the table's when this share of the frames that see it (and minPlaneVotes at
    // least) see the table's colour there; the cell's colour is their median.
    double minTableShare = 0.2;
    // A table cell's diffuse colour (PlaneAppearance::diffuseColour): this quantile of its
    // table-coloured samples. A glossy table adds the room's and the lamp's reflections in the
    // views that see them; it never takes light away, so its diffuse part is what it shows at
    // the least (a low quantile rather than the minimum, which would follow the footage's noise).
    double diffuseQuantile = 0.1;
    int minPlaneVotes = 2;
    int minObjectVotes = 3;
    double minObjectShare = 0.75;
};

// The plane's appearance and what each cell is (step 1).
struct PlaneAppearance {
    enum Cell : uint8_t { Unknown = 0, Table = 1, Covered = 2 };
    double u0 = 0, v0 = 0, cell = 0.004;  // plane coordinates of cell (0, 0)'s corner
    // CV_32FC3 linear RGB: a table cell's median table-coloured sample, any other cell's median.
    cv::Mat colour;
    // CV_32FC3 linear RGB: a table cell's diffuse colour (CarvingOptions::diffuseQuantile of its
    // table-coloured samples), for the light fit and the table's albedo; 0 elsewhere.
    cv::Mat diffuseColour;
    cv::Mat seenBy;  // CV_32S frames that see the cell
    cv::Mat kind;    // CV_8U Cell
    // The table's and the board's chromaticity (r, g over r+g+b) and brightness (r+g+b).
    cv::Vec2f tableChroma{0, 0}, boardChroma{0, 0};
    float tableBrightness = 0, boardBrightness = 0;
};

struct CarvedHeights {
    PlaneAppearance plane;
    double u0 = 0, v0 = 0, cell = 0.004;  // the height raster's corner and cell (metres)
    cv::Mat height;                       // CV_32F metres above the plane, 0 = carved to the table
    int framesUsed = 0;
    int occupiedColumns = 0;
    double seconds = 0;
};

CarvedHeights carveAbovePlane(const Footage& footage, const CarvingOptions& options = {});

}  // namespace mirage::reconstruction
