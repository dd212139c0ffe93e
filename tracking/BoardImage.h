#pragma once
// Images of a planar board's printed page (the board's sheet): raster (PNG, textures) and vector
// PDF. Both draw the same ink rectangles (boardInk()), at exact physical size.
//
// Texture mapping (for synthetic scenes that put the page on a plane): the image covers the whole
// sheet, W x H metres (Board::sheet width/height). Pixel column j, row i covers page metres
// [j*W/cols, (j+1)*W/cols) x [i*H/rows, (i+1)*H/rows), page origin top-left, +y down the page.
// With glTF texture coordinates (u, v) (origin top-left of the image):
//   page point (x, y) = (u*W, v*H);  sheet-frame point = (u*W - W/2, v*H - H/2, 0);
//   world point = T_world_sheet * sheet-frame point.
// For the default table pose that is world (x, 0, z) = (u*W - W/2, 0, v*H - H/2).
//
// Pixel values are sRGB-encoded 8-bit: white paper 255, ink 0, edge pixels hold the linear area
// coverage encoded with the sRGB curve (so decoding to linear gives exact box-filtered coverage).
#include <filesystem>
#include <vector>

#include <opencv2/core.hpp>

#include "tracking/Board.h"

namespace mirage::tracking {

// An axis-aligned black rectangle in page metres (origin top-left, +y down).
struct InkRect {
    double x, y, w, h;
};

// Every black rectangle of the page: tag cells (horizontal runs merged) and the scale bar.
// Throws mirage::Error if the board has no sheet or a tag does not lie upright in the sheet plane.
std::vector<InkRect> boardInk(const Board& board);

struct BoardRaster {
    cv::Mat image;  // CV_8UC1, sRGB-encoded (see above)
    double metresPerPixelX = 0, metresPerPixelY = 0;
};

// Renders the sheet at about pixelsPerMetre (the image size is rounded to whole pixels, and the
// exact metres-per-pixel are returned). `caption` adds the sheet's caption text (Hershey font).
BoardRaster renderBoard(const Board& board, double pixelsPerMetre, bool caption = true);

// PNG at `dpi` dots per inch (printing at 100 % gives the physical size). Atomic write.
void writeBoardPng(const std::filesystem::path& path, const Board& board, double dpi);
// Vector PDF, one page of exactly the sheet's size, tags as filled rectangles, scale bar and
// caption (Helvetica). Atomic write.
void writeBoardPdf(const std::filesystem::path& path, const Board& board);

}  // namespace mirage::tracking
