#pragma once
// Monte-Carlo trials of the tracker on degraded synthetic views of a board (docs/tracking.md,
// "Uncertainty and the ok state"): random camera poses, motion blur, exposure gain, sensor noise,
// JPEG compression and occluders, each view rendered with the known pose, tracked, and its error
// compared with the error the tracker claims (its covariance). Used by the unit test of the
// state rules and by the `tracking_montecarlo` benchmark (bigger runs).
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"
#include "tracking/Board.h"
#include "tracking/BoardImage.h"
#include "tracking/PoseEstimator.h"
#include "tracking/Tracker.h"

namespace mirage::tracking {

// Ranges the random views are drawn from (uniform unless said otherwise).
struct TrialRanges {
    double minDistanceM = 0.4, maxDistanceM = 1.2;  // camera to the aim point
    double maxTiltDeg = 55;  // angle between the viewing direction and the board normal
    // The aim point moves off the board centre by up to this fraction of the image footprint
    // (half width / height at the distance), so that parts of the board leave the image and
    // views with one or two tags occur.
    double maxAimOffset = 0.9;
    double maxBlurPx = 7;  // motion-blur length (pixels), any direction; half the views unblurred
    int minJpegQuality = 60, maxJpegQuality = 95;  // a quarter of the views not compressed
    double minGain = 0.5, maxGain = 1.6;           // exposure factor in linear light (clips at 1)
    double maxNoiseLevels = 2.0;                   // Gaussian sensor noise, sRGB levels (std)
    double occluderProbability = 0.25;             // a grey blob over part of the view
    // One-tag views: the camera aims at a random tag (offset by up to maxAimOffset of the tag's
    // image footprint) and everything but that tag and its quiet zone is painted grey, as when
    // the rest of the board is covered or out of view. Fills the one-tag condition bin, which
    // the views of the whole board reach rarely (and then mostly with an undecided planar flip).
    bool oneTagOnly = false;
};

// What degrades one view, after rendering (SyntheticBoardView, sRGB 8-bit grey).
struct Degradation {
    double blurPx = 0, blurAngleRad = 0;  // motion blur along a line, in linear light
    double gain = 1;                      // linear-light exposure factor, clipped at 1
    double noiseLevels = 0;               // std of additive Gaussian noise, sRGB levels
    int jpegQuality = 0;                  // 0: no compression
    bool occluder = false;
    cv::RotatedRect occluderShape;
    uint8_t occluderLevel = 60;
    uint64_t seed = 1;  // the noise
};

struct TrialView {
    Pose truth;            // T_world_camera
    int onlyTagId = -1;    // the tag left visible (TrialRanges::oneTagOnly), else -1
    double distanceM = 0;  // camera centre to the board centre
    Degradation degradation;
    cv::Mat image;  // 8-bit grey, sRGB-encoded
};

// Applies the degradation to an 8-bit sRGB grey image (returns a new image).
cv::Mat degradeView(const cv::Mat& grey, const Degradation& d);

// One random view: pose and degradation from `seed`, rendered (supersample: per axis).
TrialView makeTrialView(const Board& board, const BoardRaster& texture,
                        const CameraIntrinsics& camera, uint64_t seed, const TrialRanges& ranges,
                        int supersample = 2);

// Centre of the board's tags (world), the point whose distance normalises translation errors.
glm::dvec3 boardCentre(const Board& board);

// A pose estimate against the truth.
struct TrialOutcome {
    TrackingState state = TrackingState::NoTags;
    int tags = 0;             // tags used
    double minSidePx = 0;     // shortest side of the smallest used tag (pixels, from the truth)
    double distanceM = 0;     // true camera to board-centre distance
    double rotErrDeg = -1;    // -1: no pose
    double transErrRel = -1;  // translation error / distance
    // Squared Mahalanobis distances of the rotation and camera-centre errors under the reported
    // 3x3 covariance blocks (-1 when no covariance was reported).
    double mahalRot2 = -1, mahalPos2 = -1;
    double sigmaRotDeg = 0, sigmaPosRel = 0;  // sqrt of the covariance traces
    bool wrong = false;                       // a pose off by > 2 degrees or > 2 % of the distance
};
TrialOutcome scoreEstimate(const PoseEstimate& e, const Pose& truth, const Board& board,
                           const CameraIntrinsics& camera);

// Counts of one condition bin, and the table of all bins (markdown).
struct TrialBin {
    std::string name;
    int views = 0, ok = 0, uncertain = 0, ambiguous = 0, lost = 0, noPose = 0, wrongOk = 0;
    // Of the poses with a covariance (ok or uncertain): how many, how many had their rotation /
    // camera-centre error inside the 2-sigma ellipsoid (the 95.45 % region of a 3D Gaussian).
    int withCov = 0, rotIn2Sigma = 0, posIn2Sigma = 0;
    // The same for the ok poses only.
    int okRotIn2Sigma = 0, okPosIn2Sigma = 0;
    void add(const TrialOutcome& o);
};
std::string trialTable(const std::vector<TrialBin>& bins);

// One trial: the view's conditions and the tracker's outcome, plus the corner errors of the
// board tags it detected (against the projected truth) for the corner-noise measurement.
struct TrialRecord {
    uint64_t seed = 0;  // makeTrialView's seed (the view can be made again)
    double distanceM = 0;
    Degradation degradation;
    TrialOutcome outcome;
    struct TagCorners {
        double sidePx = 0;        // shortest side under the true pose
        double rmsErrPx = 0;      // corner error RMS (2D, per corner) against the truth
        double edgeWidthPx = -1;  // tagEdgeWidthPx of the detection
        // The corner errors split into what the 4 corners share: the mean radial error
        // (outwards from the tag centre: a scale change), the mean error (a shift), and the
        // RMS per coordinate of what is left (independent noise).
        double scalePx = 0;
        glm::dvec2 shiftPx{0.0};
        double independentPx = 0;
    };
    std::vector<TagCorners> tags;
    // What the pose came from: the true pose and the tracker's detections (with the edge width
    // it measured), so that the same views can be scored under other pose options
    // (rescoreTrials) without rendering and detecting again.
    Pose truth;
    std::vector<TagDetection> detections;
};

// Runs `count` views (seeds firstSeed, firstSeed + 1, ...) through one Tracker (frames 10 s
// apart: no previous pose carries over), single-threaded.
std::vector<TrialRecord> runTrials(const Board& board, const CameraIntrinsics& camera,
                                   uint64_t firstSeed, int count, const TrialRanges& ranges,
                                   const TrackerOptions& options = {}, int supersample = 2);

// The records' detections estimated again with other pose options (each view alone, as in
// runTrials: no previous pose), scored against the truth; conditions and corner data kept.
std::vector<TrialRecord> rescoreTrials(const std::vector<TrialRecord>& records, const Board& board,
                                       const CameraIntrinsics& camera,
                                       const PoseEstimatorOptions& options);

// The condition bins of docs/tracking.md: all views; by blur, JPEG quality, distance, tags
// used, smallest used tag, occluder.
std::vector<TrialBin> binTrials(const std::vector<TrialRecord>& records);

// Corner error RMS of detected tags by blur and tag side (markdown tables), and its split into
// independent, per-tag scale, per-tag shift and frame-wide scale parts against the model's sigma0
// (PoseEstimatorOptions).
std::string cornerNoiseSplitTable(const std::vector<TrialRecord>& records,
                                  const PoseEstimatorOptions& model);
// Corner error RMS of detected tags by blur and tag side (markdown table).
std::string cornerNoiseTable(const std::vector<TrialRecord>& records);

// The 95.45 % quantile of the chi-square distribution with 3 degrees of freedom (the squared
// radius of the 2-sigma ellipsoid of a 3D Gaussian).
constexpr double kChi2ThreeDof2Sigma = 8.0249;

}  // namespace mirage::tracking
