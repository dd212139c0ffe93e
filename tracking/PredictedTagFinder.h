#pragma once
// Tracking mode of the detector (docs/tracking.md, "Tracking mode"): in video, when the camera
// pose of the new frame can be predicted, the board's tags are found where the predicted pose
// puts them instead of by libapriltag's quad search over the image.
//
// Per board tag predicted fully in view, facing the camera and large enough:
//   1. coarse edges: along each predicted border edge, profiles across the edge (search radius
//      scaled by the tag's predicted motion, at most ~1 cell) locate the strongest dark-to-bright
//      step going outward (the black border into the white quiet zone); a line is fitted per
//      edge with outlier rejection and the corners are the lines' intersections;
//   2. sub-pixel corners: Detector::refineCorners, the same refinement as after libapriltag;
//   3. verification: every cell of the tag (border, payload bits, quiet-zone ring) is sampled
//      through the homography of the refined corners and compared with the cell pattern of the
//      tag id the board expects there (libapriltag's code table). A tag is kept only if at most
//      a few cells disagree and black and white cells differ clearly in brightness; a neighbour
//      tag, a shifted grid (edges locked one cell off), an occluder or an unrelated image fail.
// The caller decides what to do when too few tags survive (the Tracker falls back to
// libapriltag's search of the region of interest).
#include <array>
#include <vector>

#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"
#include "tracking/Board.h"
#include "tracking/Detector.h"

namespace mirage::tracking {

struct TagPredictionOptions {
    // Only tags whose predicted shortest side is at least this (pixels) are followed: smaller
    // tags have cells too small for a reliable edge search and bit check. (The pose estimator
    // uses tags from 10 px; libapriltag with decimate 2 misses most tags under ~25 px.)
    double minSidePx = 12.0;
    // ... and whose predicted cell size across each border edge (foreshortened) is at least this.
    double minCellPx = 1.5;
    // Edge search radius across each predicted edge (pixels): searchBasePx + searchMotionFactor x
    // the tag's predicted corner motion since the previous frame (a prediction error grows with
    // the motion), at most searchMaxCells cells: beyond ~1 cell inside the border the payload
    // bits have edges of the same polarity.
    double searchBasePx = 2.5;
    double searchMotionFactor = 0.5;
    double searchMaxCells = 1.2;
    // Search radius once the predictions are corrected by an affine map fitted to three or more
    // verified tags (PredictedTagFinder::find); a tag that fails is tried again with the full one.
    double searchCorrectedPx = 2.0;
    // Verification: cells of the border square (border + payload) that may disagree with the
    // expected pattern (36h11 codes differ in >= 11 bits), cells of the quiet-zone ring outside
    // the border that may disagree, and the least brightness difference between the expected
    // white and black cells (8-bit sRGB levels).
    int maxInnerCellErrors = 2;
    int maxOuterCellErrors = 3;
    double minContrastLevels = 15.0;
};

// Why a predicted tag was not returned (counts per frame, for tests and diagnostics).
struct PredictedTagStats {
    int predicted = 0;     // tags predicted fully in view, facing the camera, large enough
    int verified = 0;      // returned
    int edgeFailed = 0;    // an edge not found along most of its length, or not straight
    int refineFailed = 0;  // the sub-pixel refinement could not measure an edge
    int decodeFailed = 0;  // cells disagree with the expected code or too little contrast
};

class PredictedTagFinder {
public:
    // Throws mirage::Error for an unknown family or a tag id outside it.
    PredictedTagFinder(const Board& board, CameraIntrinsics camera,
                       TagPredictionOptions options = {});

    // Tags of the board found around where T_world_camera_predicted puts them in `grey` (8-bit,
    // sRGB-encoded, the camera's full image). T_world_camera_previous (the pose the prediction
    // started from) sets the search radius per tag from the predicted motion. Corners in
    // OpenCV pixel convention, libapriltag's order, as Detector::detect returns them; `hamming`
    // is the number of disagreeing cells, `decisionMargin` the black/white contrast (levels).
    std::vector<TagDetection> find(const cv::Mat& grey, const Pose& T_world_camera_predicted,
                                   const Pose& T_world_camera_previous,
                                   PredictedTagStats* stats = nullptr) const;

    // The same around where a pose estimated in this very frame puts the tags (the single-frame
    // coarse-to-fine path of the Tracker: the pose from the few large tags libapriltag found on a
    // strongly decimated image), every tag searched within searchPx (pixels, still at most
    // searchMaxCells cells). Tags in `known` (board tags found otherwise in this frame) are
    // returned as they are, counted as predicted and verified if they are predicted, and their
    // offsets correct the predictions of the others.
    std::vector<TagDetection> find(const cv::Mat& grey, const Pose& T_world_camera_estimated,
                                   double searchPx, const std::vector<TagDetection>& known,
                                   PredictedTagStats* stats = nullptr) const;

    // Verification alone (step 3 above) of corners claimed to be tag `id` of the board: the
    // number of disagreeing cells of the border square and of the quiet-zone ring and the
    // contrast; true if within the options' limits. False for an id not on the board, an image
    // that is not 8-bit grey, or cells outside the image.
    bool verify(const cv::Mat& grey, int id, const std::array<glm::dvec2, 4>& corners,
                int* innerErrors = nullptr, int* outerErrors = nullptr,
                double* contrast = nullptr) const;

    const TagPredictionOptions& options() const { return options_; }

private:
    struct TagModel {
        int id = 0;
        std::array<glm::dvec3, 4> world{};    // detection corners in the world
        glm::dvec3 centre{0.0}, normal{0.0};  // tag centre, tag +Z (into the tag) in the world
        std::vector<uint8_t> pattern;         // totalWidth^2 cells, row-major, 0 black 255 white
    };
    const TagModel* model(int id) const;
    // Both find()s: per-tag radius from the motion since T_world_camera_previous when given,
    // else searchPx.
    std::vector<TagDetection> findImpl(const cv::Mat& grey, const Pose& T_world_camera_predicted,
                                       const Pose* T_world_camera_previous, double searchPx,
                                       const std::vector<TagDetection>* known,
                                       PredictedTagStats* stats) const;
    enum class Outcome { Verified, EdgeFailed, RefineFailed, DecodeFailed };
    // A board tag predicted in view: its corners (pixels), edge search radius (pixels) and
    // shortest side (pixels).
    struct Candidate {
        const TagModel* model;
        std::array<glm::dvec2, 4> pred;
        double search, minSide;
    };
    // The board tags that face the camera at the predicted pose, large enough to verify and with
    // their quiet zone and search inside the image. Without a previous pose every search radius
    // is searchPx; with one it grows with the corners' motion since it.
    std::vector<Candidate> predictCandidates(const cv::Mat& grey,
                                             const Pose& T_world_camera_predicted,
                                             const Pose* T_world_camera_previous,
                                             double searchPx) const;
    // Steps 1-3 for one tag from its predicted corners `pred` (pixels) with edge search radius
    // `search` (pixels, before the cap of searchMaxCells); t = the verified detection.
    Outcome follow(const cv::Mat& grey, const TagModel& m, const std::array<glm::dvec2, 4>& pred,
                   double search, TagDetection& t) const;

    CameraIntrinsics camera_;
    TagPredictionOptions options_;
    int widthAtBorder_ = 8, totalWidth_ = 10;
    std::vector<TagModel> tags_;
};

}  // namespace mirage::tracking
