#pragma once
// Renders what a camera sees of a printed board's sheet, for tests and benchmarks: the board's
// raster on the sheet plane through core's TexturedPlaneRenderer (each sub-pixel unprojected with
// the camera model, the texture sampled bilinearly, sub-pixels averaged in linear light).
// Pixel (0,0) is the centre of the top-left pixel (OpenCV).
//
// Output: 8-bit grey, sRGB-encoded; ink and paper levels mix in linear light.
#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"
#include "tracking/Board.h"
#include "tracking/BoardImage.h"

namespace mirage::tracking {

struct SyntheticViewOptions {
    int supersample = 3;      // samples per pixel along each axis
    uint8_t paper = 215;      // sRGB level of white paper
    uint8_t ink = 30;         // sRGB level of black ink
    uint8_t background = 90;  // sRGB level where the ray misses the sheet
};

// `texture` = renderBoard(board, ppm) of the same board (choose ppm so a texel is no larger than
// a supersample). Throws mirage::Error if the board has no sheet or the intrinsics are invalid.
cv::Mat renderSyntheticBoardView(const Board& board, const BoardRaster& texture,
                                 const CameraIntrinsics& camera, const Pose& T_world_camera,
                                 const SyntheticViewOptions& options = {});

}  // namespace mirage::tracking
