#pragma once
// What the camera is shown: an OpenCV chessboard, an OpenCV ChArUco board, or one of mirage's
// planar AprilTag boards (the board files of tracking/Board.h). Turns an image into a
// CalibrationView: detected corners in pixels and the matching points in the board plane
// (metres, z = 0).
//
// Command-line forms (docs/calibration.md):
//   chessboard:COLSxROWS:SQUARE_METRES  inner corners, e.g. chessboard:9x6:0.025 for a board of
//                                       10x7 squares of 25 mm
//   charuco:SQUARESXxSQUARESY:SQUARE_METRES:MARKER_METRES[:DICTIONARY]
//                                       squares (not corners), e.g.
//                                       charuco:5x7:0.04:0.02:DICT_6X6_250 (the default dictionary)
//   the path of a board file
#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "calibration/Calibrator.h"
#include "calibration/SyntheticViews.h"
#include "core/math/Pose.h"
#include "tracking/Board.h"

namespace mirage::calib {

// An OpenCV (contrib 4.6) ChArUco board: a chessboard of squaresX x squaresY squares with an
// ArUco marker in every white square. Its inner corners are the calibration points: corner id i
// sits at ((i % (squaresX-1)) + 1, (i / (squaresX-1)) + 1) * squareMetres in the board frame
// (OpenCV's CharucoBoard::chessboardCorners, z = 0).
struct CharucoGeometry {
    int squaresX = 5, squaresY = 7;
    double squareMetres = 0.04, markerMetres = 0.02;
    std::string dictionary = "DICT_6X6_250";  // a cv::aruco::PREDEFINED_DICTIONARY_NAME
};

struct TargetDetection {
    bool found = false;
    CalibrationView view;  // valid when found
    std::string reason;    // why not found (for reports)
};

class CalibrationTarget {
public:
    enum class Kind { Chessboard, TagBoard, Charuco };

    // Parses the command-line form. Throws mirage::Error (malformed spec) or FileError (board
    // file) saying what is expected.
    static CalibrationTarget parse(const std::string& spec);
    static CalibrationTarget chessboard(const ChessboardGeometry& geometry);
    // Throws mirage::Error for an unknown dictionary, too few squares, a marker that does not fit
    // its square, or more markers than the dictionary has.
    static CalibrationTarget charuco(const CharucoGeometry& geometry);
    // A planar tag board. Throws mirage::Error if its tags do not lie in one plane.
    static CalibrationTarget tagBoard(const tracking::Board& board);

    CalibrationTarget(CalibrationTarget&&) noexcept;
    CalibrationTarget& operator=(CalibrationTarget&&) noexcept;
    ~CalibrationTarget();

    Kind kind() const { return kind_; }
    const ChessboardGeometry& chessboardGeometry() const { return chessboard_; }
    const CharucoGeometry& charucoGeometry() const { return charucoGeometry_; }
    // The printable ChArUco pattern (8-bit grey, white margin of marginPx), pixelsPerSquare per
    // square. Throws mirage::Error if this target is not a ChArUco board.
    cv::Mat drawCharuco(int pixelsPerSquare, int marginPx) const;
    std::string description() const;  // "chessboard 9x6 inner corners, 25.0 mm squares"
    // Every board point (metres, board plane z = 0): for drawing and coverage.
    const std::vector<cv::Point3f>& allBoardPoints() const { return allPoints_; }
    // T_world_board: the board plane frame in the world (identity for a chessboard, whose world
    // is its own frame). Used for a camera's pose relative to the world board.
    const Pose& worldFromBoard() const { return T_world_board_; }

    // Detects the target in an 8-bit image (grey or BGR, sRGB-encoded as cameras deliver it).
    // Not thread-safe (the tag detector keeps state).
    TargetDetection detect(const cv::Mat& image, const std::string& name) const;
    // A cheap test for the wizard's live overlay: true if a chessboard seems present (OpenCV's
    // fast check on a downscaled copy). Tag boards always return true (detection is fast).
    bool quickCheck(const cv::Mat& grey) const;

private:
    CalibrationTarget() = default;
    Kind kind_ = Kind::Chessboard;
    ChessboardGeometry chessboard_;
    std::vector<cv::Point3f> allPoints_;
    Pose T_world_board_;
    struct TagState;
    std::unique_ptr<TagState> tags_;
    CharucoGeometry charucoGeometry_;
    struct CharucoState;
    std::unique_ptr<CharucoState> charuco_;
};

}  // namespace mirage::calib
