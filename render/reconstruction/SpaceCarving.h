#pragma once
// Objects on the table from their silhouettes against the known plane (docs/reconstruction.md,
// "Space carving"). Real objects often have plain faces where photo-consistency stereo finds no
// depth; but the table's plane and every camera pose are known, so each pixel can be asked
// whether it shows the table where its ray meets the plane:
//  1. the plane's appearance: every cell of the plane (cellM) is projected into every frame and
//     its colour taken as the median over the frames (a diffuse table looks the same from
//     every view; an object standing in front of a cell in a few views does not move the
//     median). Cells whose median is not the table's (or the board's) colour are covered by
//     something in most views: the footprints of objects, never seen, or whatever lies beyond
//     the table's edge. The table is the connected region of table-coloured cells around the
//     board, its enclosed holes are footprints;
//  2. each pixel is classed: its ray meets the plane in a table cell and its colour matches the
//     cell's (the table is seen: nothing stands on that ray above the plane), or it does not
//     (something above the plane), or its ray ends off the table (unknown: says nothing). Where
//     the ray meets a covered cell, the pixel sees the table when its colour is the table's
//     (the few frames that see behind an object);
//  3. a voxel column over the plane is carved bottom-up: a voxel is empty when at least
//     minPlaneVotes frames see the table through it, occupied when at least minObjectVotes
//     frames (and minObjectShare of those deciding) see something above the plane there. A
//     single frame never carves (a mistracked frame, noise), and nothing is made where the
//     frames only see off the table.
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
