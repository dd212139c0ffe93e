#pragma once
// Which canvas tiles (kCausticTileSize = 8 pixels square) the caustic resolve must shade
// (CausticPass): those a photon's kernel reached this frame, and those whose receivers can take a
// non-zero caustic from last frame's history. The history part is found on the CPU from last
// frame's tiles: each tile that held caustic light is a slab of last frame's view (its pixels'
// rays, between the nearest and farthest camera distance its resolved pixels had, widened by the
// history's same-surface tolerance), projected into this frame's canvas. The slabs are
// conservative: a pixel whose surface reprojects onto a tile with caustic history, at a distance
// the same-surface test can pass, lies in a marked tile.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "render/GpuTypes.h"  // kCausticTileSize

namespace mirage::render {

// Last frame's resolve, per tile of its canvas (row-major, tilesX * tilesY).
struct CausticHistoryTiles {
    int tilesX = 0, tilesY = 0;
    std::vector<std::uint32_t> lit;  // 1: some pixel's smoothed irradiance was not 0
    std::vector<float> nearM, farM;  // camera distance range (m) of the pixels resolved there;
                                     // near > far: none resolved
};

// The two cameras of the reprojection (world -> GL clip, canvas pixels).
struct CausticReprojection {
    glm::mat4 viewProj{1.0f};       // this frame's
    glm::mat4 prevViewProj{1.0f};   // last frame's
    glm::vec3 prevCameraPos{0.0f};  // world (m)
    int width = 0, height = 0;      // canvas (both frames)
    glm::vec3 cameraPos{0.0f};      // this frame's, world (m)
};

// Marks (sets to 1) in `marks` (this frame's tiles, row-major, same grid) every tile a pixel of
// which can reproject onto a lit history tile with its camera distance within the history's
// same-surface tolerance (temporal.glsl historyIsSameSurface). A slab reaching behind this
// frame's camera marks every tile.
void markHistoryTiles(const CausticHistoryTiles& history, const CausticReprojection& cameras,
                      std::vector<std::uint8_t>& marks);

// The share (0..1) of this frame's canvas that last frame's did not show, for surfaces at
// camera distances in [nearM, farM] (m): a grid of this frame's pixels, each taken at the nearest,
// middle and farthest distance along its ray, counts as new when one of the three falls outside
// last frame's canvas or behind its camera. A frame that reuses the caustic's history has no
// caustic on what is new (the history holds only what last frame saw).
float newViewShare(const CausticReprojection& cameras, float nearM, float farM);

// The marked tiles as quads in GL normalised device coordinates, two triangles (six xy
// vertices) per run of marked tiles along a row, clipped to the canvas.
std::vector<glm::vec2> tileQuads(const std::vector<std::uint8_t>& marks, int tilesX, int tilesY,
                                 int width, int height);

}  // namespace mirage::render
