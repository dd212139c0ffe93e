#pragma once
// Geometry of the real proxies from depth maps (docs/reconstruction.md):
//  1. the depth maps are fused in a truncated signed distance volume (Open3D's
//     ScalableTSDFVolume, sparse blocks, so only the observed space costs memory) and meshed by
//     marching cubes; small disconnected pieces (stereo outliers) are dropped;
//  2. the table: the board's plane, extended over the connected region where the fused surface
//     agrees with it (within `planeBandM`); beyond it the footage sees something else (the
//     floor far below, a wall) or nothing;
//  3. objects: the fused surface above the plane, as a height field over it (4 mm cells), split
//     into connected footprints; each becomes a closed solid standing on the plane (the sides
//     and the back that no camera saw are closed straight down, where the plane continues),
//     simplified to a triangle budget by quadric decimation.
// Heights and extents are metres in the plane's frame (BoardPlane::toPlane).
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "render/reconstruction/Footage.h"
#include "render/reconstruction/SpaceCarving.h"
#include "render/reconstruction/StereoDepth.h"

namespace mirage::reconstruction {

struct GeometryOptions {
    double voxelM = 0.004;             // TSDF voxel
    double truncationM = 0.016;        // TSDF truncation distance (4 voxels)
    double planeBandM = 0.008;         // |height| below this counts as on the plane
    double cellM = 0.004;              // object height-field cell
    double minObjectHeightM = 0.015;   // lower bumps are the table's (stereo noise, paper)
    double minObjectAreaM2 = 0.0006;   // footprint (6 cm^2)
    double maxTableHalfExtentM = 1.5;  // search radius for the table's extent
    double maxHeightM = 0.5;           // objects taller than this are cut (walls, people)
    double maxDepthBelowM = 0.1;       // fused below the plane (the table's edge)
    int minComponentTriangles = 60;    // fused pieces smaller than this are outliers
    // Triangles per object after simplification; the whole scene of proxies stays within
    // maxObjects x this (the real-time renderer draws real proxies into every shadow and
    // imperfect shadow map: a few thousand triangles each keep those passes cheap).
    int triangleBudgetPerObject = 1500;
    int maxObjects = 16;
    // Carved objects are cut at the fused surface's height where it has this many points over
    // them (ProxyGeometry.cpp, capByFusedSurface).
    int minFusedSamples = 20;
};

struct TableEstimate {
    BoardPlane plane;  // the board's plane; the extent below is in its (u, v) coordinates
    double uMin = 0, uMax = 0, vMin = 0, vMax = 0;
    int supportPoints = 0;      // fused vertices within the plane band, in the extent
    double rmsHeightM = 0;      // RMS height of those above/below the plane
    double filledFraction = 0;  // of the extent's 1 cm cells that hold a supporting point
};

struct ProxyObject {
    std::string name;
    std::vector<glm::vec3> positions;  // world, metres
    std::vector<uint32_t> indices;     // triangle list, counter-clockwise from outside
    glm::dvec3 centre{0.0};            // world, of the footprint at table height
    double heightM = 0, footprintM2 = 0;
    double sizeU = 0, sizeV = 0;  // footprint's extent along the board axes (metres)
    int observedCells = 0;        // cells with fused surface (the rest closed by filling)
    // Linear sRGB-primaries colour of the fused surface (camera units, average over the top),
    // filled in by the material step.
    glm::dvec3 observedColour{0.0};
    // Surface points (world) with their fused linear colour and normal, for the material and
    // light steps.
    std::vector<glm::vec3> samplePoints, sampleColours, sampleNormals;
};

struct FusedGeometry {
    TableEstimate table;
    std::vector<ProxyObject> objects;
    int fusedVertices = 0, fusedTriangles = 0, droppedComponents = 0;
    // The table's observed colour per cell of tableCellM (linear camera units, RGB; rows along
    // v from vMin, columns along u from uMin, over the extent), CV_32FC3, and the mask of the
    // cells that were observed (CV_8U, 255 = observed).
    cv::Mat tableColour, tableObserved;
    double tableCellM = 0.004;
};

// `carved`: the objects' heights from space carving (SpaceCarving.h) instead of the fused
// surface's; the fusion still gives the table's extent, its colour and the objects' colour
// samples.
FusedGeometry reconstructGeometry(const Footage& footage, const std::vector<DepthView>& views,
                                  const GeometryOptions& options = {},
                                  const CarvedHeights* carved = nullptr);

}  // namespace mirage::reconstruction
