#pragma once
// Extended tracking from natural features (docs/tracking.md, "Extended tracking"): while the board
// gives the camera pose, corners elsewhere in the image (Shi-Tomasi, cv::goodFeaturesToTrack) are
// followed from frame to frame by pyramidal Lucas-Kanade (cv::calcOpticalFlowPyrLK, checked
// forwards and backwards) and placed in the world as landmarks (LandmarkMap: inverse depth with
// uncertainty, refined from every board pose that sees them). When the board's tags no longer
// give an ok pose, the pose comes from the landmarks: PnP with RANSAC (cv::solvePnPRansac, AP3P)
// against the landmarks' current point estimates, then Levenberg-Marquardt (core/math) on the
// landmarks' reprojection errors, each whitened by its own projected uncertainty (so a landmark
// of unknown depth still constrains the rotation of a camera that only turned), with the corners
// of any board tags still seen as further observations. The pose's covariance adds the error the
// map inherits from the board poses that built it; ok / uncertain / lost are decided by the same
// bounds as for tags (PoseEstimatorOptions::okMaxSigma*), after consistency checks (inliers,
// their share of the tracked landmarks, their spread over the image, the whitened RMS).
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "tracking/LandmarkMap.h"
#include "tracking/PoseEstimator.h"

namespace mirage::tracking {

struct FeatureTrackingOptions {
    bool enabled = true;
    // Features kept at 640 pixels of image width (scaled with the width).
    int maxFeatures = 150;
    // New features are detected every detectEvery-th frame with a known pose, or as soon as fewer
    // than refillFraction x maxFeatures are tracked.
    int detectEvery = 5;
    double refillFraction = 0.6;
    double minDistancePx = 14.0;  // between features, at 640 pixels of width
    double cornerQuality = 0.01;  // cv::goodFeaturesToTrack qualityLevel
    int kltWindowPx = 21;         // at 640 pixels of width
    int kltLevels = 4;
    // KLT's stop per pyramid level: this many iterations, or a step below kltEpsilonPx (pixels
    // of that level).
    int kltMaxIterations = 20;
    double kltEpsilonPx = 0.03;
    // With a predicted pose the forward track first searches the pyramid levels up to this one
    // only (the prediction is usually a few pixels off); the tracks that pass lose nothing, the
    // others are tracked again over all kltLevels from the same start. 0: all levels at once.
    int kltFirstLevels = 2;
    // A track whose backward track misses its start by more than this is dropped (pixels).
    double forwardBackwardMaxPx = 0.5;
    // Pyramid levels above the full image searched by the backward track. It starts where the
    // forward track began, so a track that held comes back without the coarse levels; one that
    // slid is still rejected when it does not come back within forwardBackwardMaxPx. Fewer
    // levels than kltLevels make the check cheaper.
    int backwardLevels = 1;
    // Feature position noise (pixels, per coordinate) and of the tag corners used with them.
    double featureSigmaPx = 0.35;
    double tagCornerSigmaPx = 0.3;
    // A new landmark's inverse depth is 1 / (the board's distance) with this relative standard
    // deviation until other views refine it.
    double rhoSigmaFraction = 1.0;
    // Observations are stored when the camera moved or turned this much from the stored ones.
    double minBaselineM = 0.004;
    double minTurnDeg = 1.0;
    // A landmark whose views disagree (RMS over its observations, pixels) or whose track leaves
    // its prediction at a board pose by more than maxLandmarkChi2 (whitened, 2 dof) is removed
    // (a moving object, a track that slid).
    double maxLandmarkRmsPx = 1.5;
    double maxLandmarkChi2 = 16.0;
    // Pose from landmarks: RANSAC, then inliers by whitened residual (2 dof) below inlierChi2.
    int ransacIterations = 80;
    double ransacThresholdPx = 3.0;
    double inlierChi2 = 12.0;
    // Consistency checks for ok: at least minInliers, at least minInlierFraction of the landmarks
    // tracked into the frame, an inlier box of at least minSpreadFraction of the image, and a
    // whitened RMS of at most maxWhitenedRms.
    int minInliers = 20;
    double minInlierFraction = 0.6;
    double minSpreadFraction = 0.08;
    double maxWhitenedRms = 1.6;
    // Features are tracked only this long after the last ok pose (seconds).
    double maxGapS = 0.5;
    // The camera centre of a pose from features is held near the motion model's prediction:
    // a prior with the last pose's covariance plus this unmodelled acceleration (m/s^2, per
    // axis) over the time since that pose. A pan seen only through landmarks of unknown depth
    // constrains the rotation, not the centre; the prior says how far a hand-held camera's
    // centre can stray from its motion in that time. 0: no prior.
    double centreAccelSigma = 0.5;
    // Landmarks may be created from poses of the features themselves (a pan into unseen parts
    // of the scene); their uncertainty includes that pose's.
    bool derivedLandmarks = true;
};

// A prior on the camera centre of a pose from features (world, metres): residual
// W (c - centre) with W = L^-1 for the prior's covariance L L^T (unit covariance). Inactive: none.
struct CentrePrior {
    glm::dvec3 centre{0.0};
    glm::dmat3 W{0.0};
    bool active = false;
};

// How the frame's pose was made: tags alone, tags and features together, features alone.
enum class TrackingMode { Board, BoardAndFeatures, FeaturesOnly };
// "board", "board+features", "features only".
const char* trackingModeName(TrackingMode m);

struct FeatureStats {
    int tracked = 0;    // tracks carried into this frame
    int landmarks = 0;  // of them with a landmark in view
    int inliers = 0;    // landmarks in the pose (0 when no pose was tried)
    int tags = 0;       // tags in the pose
    int detected = -1;  // corners the frame's detection added (-1: no detection ran)
    double trackMs = 0, poseMs = 0, mapMs = 0;
};

class FeatureTracker {
public:
    FeatureTracker(Board board, CameraIntrinsics camera, FeatureTrackingOptions options = {},
                   PoseEstimatorOptions bounds = {});

    // Follows the tracked features into the new frame (8-bit grey). Call once per frame first.
    // predicted: the frame's expected T_world_camera (motion model), where each landmark's
    // search starts; without it the search starts at the feature's last position. The previous
    // frame's deferred detection (see learn) runs first when `predicted` is given (the frames
    // are a video), and is dropped otherwise.
    void track(const cv::Mat& grey, const std::optional<Pose>& predicted = std::nullopt);
    // The frame's pose is known (state ok): refine the landmarks, drop those that disagree, and
    // detect new features where there are none. fromBoard: the pose came from tags alone (else
    // from the landmarks; new landmarks are then `derived`). boardPixels: the board's image box
    // under the pose (no features there: the tags are tracked on their own). A frame that had
    // nothing to track (the first of a video, or an unrelated single frame) defers its detection
    // to the next call of track: single frames do not pay for features no later frame follows.
    void learn(const cv::Mat& grey, const PoseEstimate& pose, bool fromBoard,
               const cv::Rect& boardPixels);
    // Pose from the tracked landmarks and the board tags among `tags`, starting near `predicted`
    // (T_world_camera). The camera centre has a prior (options: centreAccelSigma): the last
    // pose given to learn moved by `velocity` (world, m/s) over sinceLastPoseS seconds (<= 0: no
    // prior). State ok only when the checks pass (see above); pose unset when none was found.
    PoseEstimate estimate(const Pose& predicted, const std::vector<TagDetection>& tags,
                          double sinceLastPoseS = 0, const glm::dvec3& velocity = glm::dvec3(0.0));
    // Forgets everything (the next frame starts without tracks).
    void reset();

    const FeatureStats& stats() const { return stats_; }
    const LandmarkMap& map() const { return map_; }
    // Image positions of the tracked features that have a landmark (pixels), for display.
    std::vector<cv::Point2f> trackedPixels() const;
    const FeatureTrackingOptions& options() const { return options_; }

private:
    struct Track {
        cv::Point2f px;
        int landmark = -1;
    };
    struct Correspondence;
    // KLT from `from` to `to` (pyramids) over `levels` levels, starting at `next` (in: the
    // start, out: the result), checked backwards; per point whether the track holds.
    std::vector<uchar> trackForwardBackward(const std::vector<cv::Mat>& from,
                                            const std::vector<cv::Mat>& to, int win, int levels,
                                            const std::vector<cv::Point2f>& prev,
                                            std::vector<cv::Point2f>& next) const;
    // The prior on the camera centre (inactive without a last pose).
    CentrePrior centrePrior(double sinceLastPoseS, const glm::dvec3& velocity) const;
    std::vector<Correspondence> correspondences(const Pose& at) const;
    // A start pose from PnP + RANSAC over the landmarks' point estimates (none: too few agree).
    std::optional<Pose> ransacStart(const std::vector<Correspondence>& corr) const;
    // What the pose fit found, for the ok/uncertain/lost decision.
    struct FitQuality {
        size_t inliers = 0, landmarks = 0, tags = 0;
        double whitenedRms = 0;
        double spread = 0;  // the inliers' image box as a share of the image
        bool covarianceOk = false, converged = false;
    };
    // Sets e.state and e.reason: the same bounds as for tags, after the consistency checks.
    void judge(PoseEstimate& e, const FitQuality& q) const;
    void detect(const cv::Mat& grey, const PoseEstimate& pose, bool derived,
                const cv::Rect& boardPixels);
    // A detection left for the next frame (learn on a frame with nothing tracked).
    struct DeferredDetection {
        PoseEstimate pose;
        bool derived = false;
        cv::Rect boardPixels;
    };

    Board board_;
    CameraIntrinsics camera_;
    FeatureTrackingOptions options_;
    PoseEstimatorOptions bounds_;
    std::vector<cv::Mat> pyramid_;  // previous frame's (empty when it had nothing to track)
    cv::Mat previousGrey_;          // previous frame's image, for a deferred detection
    std::optional<DeferredDetection> deferred_;
    std::vector<Track> tracks_;
    LandmarkMap map_;
    int framesSinceDetect_ = 0;
    // The last detection found fewer corners than it looked for: the view has no more texture
    // to give, so the refill waits for the periodic detection (detectEvery) instead of running
    // in every frame.
    bool lastDetectionShort_ = false;
    // Running mean of the covariances of the board poses that built the map: the error every
    // landmark shares (added to the pose's covariance).
    std::array<double, 36> mapCovariance_{};
    // Covariance of the last pose from the landmarks (shared by the derived landmarks).
    std::array<double, 36> derivedCovariance_{};
    // Covariance of the last pose given to learn (the centre prior's starting error).
    std::optional<std::array<double, 36>> lastPoseCovariance_;
    glm::dvec3 lastCentre_{0.0};  // of the last pose given to learn (world, metres)
    double scale_ = 1.0;          // image width / 640
    FeatureStats stats_;
};

}  // namespace mirage::tracking
