#pragma once
// A textured tabletop with a board's sheet on it, rendered in process for tests and benchmarks of
// extended tracking (docs/tracking.md, "Extended tracking"): the sheet pasted into a large plane of
// value noise at millimetre scales (like wood grain or stone), seen through core's
// TexturedPlaneRenderer (exact camera model, supersampled). The plane is the sheet's plane; the
// world is the board's (glTF: metres, +Y up).
#include <cstdint>

#include <opencv2/core.hpp>

#include "core/camera/TexturedPlaneRenderer.h"
#include "core/math/Pose.h"
#include "tracking/Board.h"

namespace mirage::tracking {

// Grey value noise (8-bit, levels 25..230) summing three octaves: cells of size/64, size/16 and
// size/6 pixels' worth of detail, seeded.
cv::Mat valueNoiseTexture(int size, uint32_t seed);

class SyntheticTabletop {
public:
    // The table: 2 halfSizeM x 2 halfSizeM metres of noise at metresPerTexel, centred on the
    // sheet, with the sheet's raster at its place. Throws mirage::Error for a board without sheet.
    explicit SyntheticTabletop(Board board, double halfSizeM = 1.0, double metresPerTexel = 0.0005,
                               uint32_t seed = 7);

    // 8-bit grey view (sRGB-encoded) of the camera at T_world_camera.
    cv::Mat render(const TexturedPlaneRenderer& renderer, const Pose& T_world_camera) const;

    const Board& board() const { return board_; }
    const PlaneTexture& texture() const { return texture_; }

private:
    Board board_;
    PlaneTexture texture_;
};

// A camera path for extended tracking: an orbit over the board's origin (azimuth -15..15 degrees
// at distanceM, elevationDeg up, over orbitFrames), then a pan of panDeg about world +Y at the
// camera's position (eased, over panFrames) that takes the board out of view. T_world_camera.
Pose orbitThenPan(int frame, int orbitFrames, int panFrames, double panDeg, double distanceM = 0.45,
                  double elevationDeg = 50.0);

// True when a corner of a board tag projects into the image.
bool boardInView(const CameraIntrinsics& camera, const Board& board, const Pose& T_world_camera);

}  // namespace mirage::tracking
