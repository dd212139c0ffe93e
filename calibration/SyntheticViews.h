#pragma once
// Synthetic board views with known intrinsics and poses: for tests (recover known parameters,
// Monte-Carlo uncertainty checks) and for trying the wizard without a camera
// (`mirage calibrate --write-synthetic DIR`). The images come from core's TexturedPlaneRenderer:
// every sub-pixel ray-cast through the camera model onto the board plane, averaged in linear
// light, so they are exact up to the supersampling.
#include <random>
#include <vector>

#include <opencv2/core.hpp>

#include "calibration/Calibrator.h"
#include "core/camera/CameraModel.h"
#include "core/camera/TexturedPlaneRenderer.h"

namespace mirage::calib {

// An OpenCV chessboard: cols x rows INNER corners, squares of squareMetres. Corner (i, j) lies at
// (i * square, j * square, 0) in the board frame, listed row by row (OpenCV's detection order).
struct ChessboardGeometry {
    int cols = 9, rows = 6;
    double squareMetres = 0.025;
    std::vector<cv::Point3f> corners() const;
};

// Ideal fish-eye projections: the image radius of a ray theta off the axis is f * theta
// (equidistant) or 2 f sin(theta / 2) (equisolid, e.g. most 180-degree photographic fish-eyes).
enum class FisheyeLens { Equidistant, Equisolid };

// Kannala-Brandt intrinsics of an ideal fish-eye lens with a field of view of fovDeg (full angle),
// centred in a width x height image, its image circle touching the top and bottom edges. k1..k4
// are fitted to the lens's theta_d(theta) / f over 0..fov/2 (least squares; exact for
// equidistant, within 1e-5 px for equisolid up to 190 degrees at 640x480); maxFisheyeTheta is
// half the field. Throws mirage::Error for a field outside (0, 240] degrees.
CameraIntrinsics idealFisheye(FisheyeLens lens, double fovDeg, int width, int height);

// Board pose T_camera_board (Rodrigues + metres).
struct BoardPose {
    cv::Vec3d rvec, tvec;
};

// The board with its centre at `distance` (metres) along `direction` (camera frame), facing the
// camera (its normal along the line of sight), then tilted by tiltDeg about the axis at
// tiltAxisDeg in its plane and rolled by rollDeg about its normal.
BoardPose boardPoseFacing(const ChessboardGeometry& board, const cv::Vec3d& direction,
                          double distance, double tiltDeg, double tiltAxisDeg = 0,
                          double rollDeg = 0);

struct PoseSamplerOptions {
    double minDistance = 0.35, maxDistance = 0.7;  // metres, camera to board centre
    double minTiltDeg = 15, maxTiltDeg = 45;       // board tilt off fronto-parallel
    double maxRollDeg = 20;                        // rotation about the board normal
    // The board centre is placed on the ray through a random pixel; this fraction of the image
    // (around its centre) is where those pixels are drawn.
    double imageSpread = 0.7;
    bool requireFullyVisible = true;  // retry until every corner projects inside the image
    int marginPx = 6;                 // ... at least this far from the border
};

// Random board poses that face the camera (their normal within the tilt range of the ray to the
// board centre). Deterministic for a given rng state.
std::vector<BoardPose> sampleBoardPoses(const CameraIntrinsics& camera,
                                        const ChessboardGeometry& board, int count,
                                        const PoseSamplerOptions& options, std::mt19937& rng);

// The ideal corners of `board` at `pose`, plus isotropic Gaussian noise of noisePx (pixels) per
// coordinate. Corners that fall outside the image (or behind the camera) are left out, the way a
// detector would not report them.
CalibrationView projectView(const CameraIntrinsics& camera, const ChessboardGeometry& board,
                            const BoardPose& pose, double noisePx, std::mt19937& rng,
                            const std::string& name);

// Renders boards as 8-bit grey images (sRGB-encoded values: black squares 25, white 230,
// background 110), with a white margin of one square around the pattern as printed boards have.
// Pixels whose ray misses the board show the background. A thin adapter over
// TexturedPlaneRenderer (core/camera): the chessboard is a texture of one texel per square with
// nearest sampling, so its edges are exact; sub-pixels are averaged in linear light.
class ChessboardRenderer {
public:
    ChessboardRenderer(const CameraIntrinsics& camera, int supersample = 3);
    cv::Mat render(const ChessboardGeometry& board, const BoardPose& pose) const;
    // Any printed planar pattern (8-bit grey texture, row 0 at the top): texel (u, v) covers the
    // board-frame square [x0 + u*s, x0 + (u+1)*s) x [y0 + v*s, y0 + (v+1)*s) (metres, s =
    // metresPerTexel, (x0, y0) = boardOriginTexel scaled by -s), nearest texel per sub-pixel.
    // Outside the texture: the background (110).
    cv::Mat renderTexture(const cv::Mat& texture, double metresPerTexel,
                          const cv::Point2d& boardOriginTexel, const BoardPose& pose) const;

private:
    TexturedPlaneRenderer renderer_;
    static constexpr double kBackground = 110;  // grey value where a ray misses the board
};

// Blur of an 8-bit sRGB-encoded grey image as a lens or motion makes it: a Gaussian of sigmaPx
// pixels applied in linear light, then encoded again (blurring the encoded values instead shifts
// edges toward the dark side by up to ~1 px at sigma 3 when corners are refined in linear light).
cv::Mat blurInLinearLight(const cv::Mat& srgbGrey, double sigmaPx);

// One-off convenience (builds a renderer).
cv::Mat renderChessboard(const CameraIntrinsics& camera, const ChessboardGeometry& board,
                         const BoardPose& pose, int supersample = 3);

}  // namespace mirage::calib
