#pragma once
// Frame-by-frame camera tracking: detection, pose, state with a reason, temporal filtering.
// One Tracker per video stream (it keeps the previous pose for the planar ambiguity and the
// filter state). Frames are 8-bit BGR (sRGB-encoded, as cameras deliver them) or grey.
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "tracking/Detector.h"
#include "tracking/FeatureTracker.h"
#include "tracking/MissingTagRegion.h"
#include "tracking/PoseEstimator.h"
#include "tracking/PoseFilter.h"
#include "tracking/PredictedTagFinder.h"

namespace mirage::tracking {

// Temporal filter of the ok poses: the adaptive constant-velocity filter (default) or the One
// Euro filter (the previous default, kept for comparison; it lags in fast motion).
enum class FilterKind { Predictive, OneEuro };

struct TrackerOptions {
    DetectorOptions detector;
    PoseEstimatorOptions pose;
    FilterKind filterKind = FilterKind::Predictive;
    PoseFilterOptions filter;
    OneEuroOptions oneEuro;
    bool filterEnabled = true;
    // The previous ok pose helps decide the planar ambiguity only if it is this recent (seconds)
    // and was well determined: at least priorMinTags tags or a 1-sigma rotation uncertainty of
    // at most priorMaxSigmaRotDeg (a weak one-tag pose could pass its own error on).
    double priorMaxAgeS = 0.5;
    int priorMinTags = 3;
    double priorMaxSigmaRotDeg = 0.2;
    // Prediction guard (video): an ok pose that is not well determined (as above) and lies more
    // than guardMaxRotDeg or guardMaxPosFraction of the distance from the constant-velocity
    // prediction of the recent ok poses is reported uncertain: a jump that only a weak fit
    // supports is more likely a wrong pose than a motion.
    double guardMaxRotDeg = 5.0;
    double guardMaxPosFraction = 0.05;

    // When no tag is found, an image whose sharpness (strongest gradients over the intensity
    // range, about 1 / edge width in pixels) is below this is reported too_blurred, not no_tags.
    double minSharpness = 0.12;
    // Region of interest: after an ok frame (at most priorMaxAgeS old), tags are searched only
    // in the image box of the whole board projected with that pose, grown by roiMarginFraction of
    // its size plus roiMarginPx on every side (camera motion between frames). If that frame is
    // then not ok, or the board's box under the new pose is not inside the region (part of the
    // board may lie outside what was searched), it is detected again on the full image (the
    // region's origin is aligned to 8 pixels so that libapriltag's decimation and threshold
    // tiles fall as in a full search); every fullFrameEvery-th frame is
    // always searched in full. Skipped when the box covers most of the image anyway.
    bool roiEnabled = true;
    double roiMarginPx = 32.0;
    double roiMarginFraction = 0.15;
    int fullFrameEvery = 30;
    // Tracking mode (docs/tracking.md, "Tracking mode"): after an ok frame (at most priorMaxAgeS
    // old), the pose of the new frame is predicted by constant velocity from the last two ok
    // poses and the board's tags are found where it puts them (PredictedTagFinder: edge search,
    // sub-pixel refinement, verification of every cell against the expected code) instead of by
    // libapriltag's search. The frame falls back to the search (region of interest, then full
    // image, as above) when fewer than max(trackMinTags, trackMinFraction x the predicted tags)
    // are verified, or the pose from them is not ok. Every fullFrameEvery-th frame is searched
    // in full regardless (recovery, and a check of the whole image).
    bool tagTracking = true;
    TagPredictionOptions prediction;
    int trackMinTags = 2;
    double trackMinFraction = 0.5;
    // Coarse-to-fine search of a single frame (docs/tracking.md, "Single frames"): when the full
    // image must be searched (no recent ok pose, or a full search is due), libapriltag first
    // searches the image decimated by coarseDecimate (no full-resolution retry), which finds the
    // larger tags cheaply; the pose from the coarsePoseTags largest of them (ok only: outlier
    // rejection, RMS and ambiguity checks as always) predicts every board tag, and
    // PredictedTagFinder finds and verifies the others at full resolution within coarseSearchPx
    // (pixels), corrected by the offsets of libapriltag's tags. The pose from all tags is the
    // frame's. The frame falls back to the ordinary search (DetectorOptions::decimate) when the
    // coarse search finds nothing, its pose is not ok, fewer than max(trackMinTags,
    // trackMinFraction x the predicted tags) are verified, or the final pose is not ok.
    // Only for frames at least coarseMinWidth pixels wide: at 640x480 the decimated search finds
    // usable tags in too few frames to pay for itself (docs/tracking.md: equal time, measured).
    bool coarseToFine = true;
    int coarseMinWidth = 1000;
    // Textured-region search of frames without a recent ok pose (docs/tracking.md, "Single
    // frames"): libapriltag searches only the image box of the blocks that hold strong contrast
    // (texturedRegion: the printed tags' black-on-white edges), grown by textureMarginPx, when
    // that box covers at most textureMaxFraction of the image (a cluttered background spreads the
    // contrast over the image: then the full image is searched, as without it). The frame is
    // searched again on the full image when the region gave no pose or the board under that pose
    // reaches outside the region (tags the region may have cut off).
    bool textureRegion = true;
    double textureMaxFraction = 0.5;
    double textureMarginPx = 24.0;
    float coarseDecimate = 4.0f;
    double coarseSearchPx = 4.0;
    int coarsePoseTags = 4;
    // libapriltag's edge refinement (refine_edges) in the coarse search: off, mirage's corner
    // refinement takes the decimation's error (Detector::refineQuadCorners). libapriltag refines
    // every candidate quad, ~0.15 ms of each coarse search at 640x480 (docs/tracking.md,
    // "libapriltag's edge refinement in the coarse search"). The ordinary search keeps it
    // (detector.refineEdges): on blurred, compressed views its refined quads decode more tags.
    bool coarseRefineEdges = false;
    // Coarse-first single frames (docs/tracking.md, "Single frames: coarse-first search"): in a
    // frame without a recent ok pose, the textured region's size says how large the board's
    // tags are in the image (the largest tag's side, estimated as the board's largest tag over
    // its diameter times the region's diagonal; an overestimate under foreshortening). The
    // coarse-to-fine search then runs at any image width, at the largest decimation of
    // coarseFirstDecimations that leaves the estimated side at least coarseFirstMinSidePx on the
    // decimated image; when none does (small, distant tags) the ordinary search runs directly.
    // It replaces coarseMinWidth / coarseDecimate in such frames; false = those as before.
    // A decimation of 1 in the list (libapriltag at full resolution in the window below, for
    // small, distant tags; docs/tracking.md) finds more tags there than the ordinary search; it
    // is not in the default: its poses leave the covariance check of the Monte-Carlo views.
    bool coarseFirst = true;
    std::vector<float> coarseFirstDecimations{4.0f, 3.0f};
    double coarseFirstMinSidePx = 15.0;
    // The coarse-first search reads only a window about the textured region's centre, this
    // fraction of the region's width and height, grown by textureMarginPx (libapriltag's cost
    // follows the tag edges it reads; the coarse pose needs only a few tags, one large tag may
    // settle it, and the finder looks for the others). 1 (or more) = the whole grown region.
    double coarseWindowFraction = 0.5;
    // When the ordinary search of a frame without a recent ok pose finds no tag at its
    // decimation (small, distant or steep tags), libapriltag searches the coarse-first window
    // at full resolution first, and the finder the rest of the board from the pose of the tags
    // found there (the coarse-to-fine search at decimation 1); only when that gives no ok pose
    // does the whole region get the full-resolution search (DetectorOptions::
    // fullResolutionRetry). The window is about a third of the region's pixels: on the
    // benchmark's distant views it saves 10-15 % of such a frame (docs/tracking.md, "The window
    // at finer decimations"). Only where the textured region stands for the board (it was
    // searched alone), as the cascade below. False = the whole region at once.
    bool windowRetry = true;
    // When the coarse-first window holds no tag at the chosen decimation, the coarse-to-fine
    // search tries the finer decimations 3 and 2 below it in the same window, and 1 (full
    // resolution) when fullResolutionFallback is on, before the ordinary search of the whole
    // region. It stops at the first that finds a tag: a tag without a confirmed pose goes to the
    // ordinary search as before. False = the ordinary search at once.
    bool coarseFirstCascade = true;
    // Extended tracking (docs/tracking.md, "Extended tracking"): natural features tracked while
    // the board gives the pose, and the pose from them when its tags do not give an ok one
    // (board partly or wholly out of view, covered). features.enabled = false: the board only.
    FeatureTrackingOptions features;
    // When the board gives the pose again after poses from the features, the reported (filtered)
    // pose moves from where the features put it to the board's in this many equal steps.
    int reanchorFrames = 5;
    // Adaptive detection (docs/tracking.md, "Adaptive detection"): libapriltag's decimated search
    // (DetectorOptions::decimate) misses tags under ~15-25 px (distant or steep views). When it
    // found some tags but no settled pose (ok or uncertain), libapriltag searches again at full
    // resolution: where the motion prediction of the recent ok poses puts the board tags it
    // missed (video; missingTags), else the whole search region. Once a pose of the frame is
    // settled, the board tags it predicts fully in view and large enough but not found are
    // looked for by the tracking mode's finder (PredictedTagFinder, within coarseSearchPx,
    // every cell verified), and the pose is estimated again from all tags. Off = the decimated
    // search alone (then a full-resolution retry only when it finds no tag at all,
    // DetectorOptions::fullResolutionRetry).
    bool fullResolutionFallback = true;
    MissingTagOptions missingTags;
    // libapriltag's knobs for the full-resolution pass (measured in docs/tracking.md): Gaussian
    // blur before the quad search (quad_sigma; 0 = none), the sharpening of the sampled bits
    // (decode_sharpening) and the snapping of the quad's edges to the image's gradients
    // (refine_edges; libapriltag applies it at any decimation). The other detector options are
    // those of `detector`.
    float fullResolutionBlurSigma = 0.0f;
    double fullResolutionSharpening = 0.25;
    bool fullResolutionRefineEdges = true;
};

struct TrackedFrame {
    double t = 0;                  // seconds
    PoseEstimate estimate;         // state, reason, raw pose, RMS, covariance, tags
    std::optional<Pose> filtered;  // T_world_camera after the temporal filter (state ok only)
    std::vector<TagDetection> detections;
    double sharpness = -1;  // computed only when no tag was found
    double detectMs = 0, poseMs = 0, filterMs = 0;
    // The region libapriltag searched first (the full image when no region was used; empty when
    // the tracking mode gave the pose and nothing was searched), and whether the full image had
    // to be searched again because the region's result was not ok.
    cv::Rect searchRegion;
    bool fullFrameRetry = false;
    // Tracking mode: tried in this frame, its per-tag counts, and whether its tags made the
    // pose (false: the frame fell back to libapriltag's search, or the mode was not tried).
    bool tagTrackingTried = false;
    std::optional<Pose> predictedPose;  // T_world_camera the tags were predicted with
    PredictedTagStats prediction;
    bool tagTracked = false;
    // Coarse-to-fine single-frame search: tried, libapriltag's tags on the decimated image, and
    // whether it gave the pose (false: the ordinary search did).
    bool coarseTried = false;
    int coarseTags = 0;
    bool coarseUsed = false;
    // The ordinary search found no tag at its decimation and searched the coarse-first window
    // at full resolution (TrackerOptions::windowRetry); coarseUsed then says whether that gave
    // the pose.
    bool windowRetried = false;
    // The coarse-first window held no tag at the chosen decimation and was searched at a finer
    // one (TrackerOptions::coarseFirstCascade).
    bool coarseCascaded = false;
    // Coarse-first search: the largest tag's side estimated from the textured region (pixels;
    // 0 when not estimated) and the decimation it chose (0: none, the ordinary search; 1: full
    // resolution in the coarse window).
    double coarseFirstSidePx = 0;
    float coarseFirstDecimate = 0;
    // The image box libapriltag's coarse search read (pixels; empty when not tried).
    cv::Rect coarseWindow;
    // Textured-region search: the frame's search began in texturedRegion's box (searchRegion).
    bool textureRegionUsed = false;
    // Extended tracking: what made the pose (Board also when features are off or not needed),
    // the features' counts and cost (tracking, pose, map upkeep), and the share of the drift
    // still blended into `filtered` after the board came back (0: none).
    TrackingMode mode = TrackingMode::Board;
    FeatureStats features;
    double featureMs = 0;
    double reanchorWeight = 0;
    // Adaptive detection: the image box libapriltag searched again at full resolution (empty:
    // no such pass), the board tags that pass looked for (0 when it searched a whole region
    // without a pose) and how many it found; then the board tags the finder added where this
    // frame's settled pose put them.
    cv::Rect fullResolutionRegion;
    int fullResolutionSought = 0;
    int fullResolutionFound = 0;
    int fullResolutionFinderFound = 0;
};

// Sharpness of an 8-bit grey image: for each of 4 directions (0, 45, 90, 135 degrees) the 99.5th
// percentile of the directional derivative (intensity levels per pixel), the smallest of the four
// (motion blur along one direction lowers that one only), divided by the 1..99 % intensity
// range; about 1 / (edge width in pixels). 0 for an image without contrast.
double imageSharpness(const cv::Mat& grey);

// Image box (pixels) of the 8x8-pixel blocks of an 8-bit grey image whose intensity range
// (brightest minus darkest of every second pixel of every second row) is at least half the
// 99th percentile of the blocks' ranges and at least 12 levels: where printed black-on-white
// tags are, on a plain background. Empty when no block qualifies.
cv::Rect texturedRegion(const cv::Mat& grey);

// Edge width around a tag (pixels): 1 / imageSharpness of the image box of its corners grown by
// 2 px; about 2 px for a sharp image, the blur length for a motion blur longer than that.
// -1 when the box has no contrast or lies outside the image.
double tagEdgeWidthPx(const cv::Mat& grey, const std::array<glm::dvec2, 4>& corners);

class Tracker {
public:
    Tracker(Board board, CameraIntrinsics camera, TrackerOptions options = {});

    TrackedFrame process(const cv::Mat& image, double t);
    // A pose known from elsewhere (the last pose of a previous run, another sensor) acts as the
    // previous ok pose at time t: it may decide the planar ambiguity of the next frames.
    // The caller vouches for it: it counts as well determined.
    void seedPrior(const Pose& T_world_camera, double t) {
        lastOk_ = T_world_camera;
        lastOkT_ = t;
        lastOkWellDetermined_ = true;
        previousOk_.reset();
    }
    // A frame that could not be read (corrupt, truncated video): reported lost, filter reset.
    TrackedFrame markLost(double t, const std::string& reason);

    const PoseEstimator& estimator() const { return estimator_; }
    // The natural-feature tracker (nullptr when options.features.enabled is false).
    const FeatureTracker* features() const { return features_.get(); }

private:
    // The stages of process(), in order.
    // Tracking mode: the tags where the predicted pose puts them (f.tagTracked when they gave it).
    void trackPredictedTags(const cv::Mat& grey, double t,
                            const std::optional<Pose>& ambiguityPrior, TrackedFrame& f);
    // Where libapriltag searches: region of interest, textured region, coarse-first window.
    struct SearchPlan {
        cv::Rect coarseSearch;
        // The coarse-first window when the frame has one (else empty): the ordinary search's
        // full-resolution retry reads it first (TrackerOptions::windowRetry).
        cv::Rect retryWindow;
        // coarseSearch is the coarse-first window about a textured region that stands for the
        // board (TrackedFrame::textureRegionUsed): the coarse search may step to finer
        // decimations there.
        bool windowed = false;
        float coarseDecimate = 0;
        bool coarseRegion = false;
    };
    SearchPlan planSearch(const cv::Mat& grey, const std::optional<Pose>& prior, bool usePrior,
                          TrackedFrame& f);
    // libapriltag's search (coarse to fine, or ordinary) and the full-image retry.
    void searchPlanned(const cv::Mat& grey, const SearchPlan& plan,
                       const std::optional<Pose>& ambiguityPrior, double t, TrackedFrame& f);
    // No tag: too_blurred when the image is blurred.
    void classifyNoTags(const cv::Mat& grey, TrackedFrame& f) const;
    // Natural features: learn from an ok board pose, or give the pose when the tags did not.
    void extendWithFeatures(const cv::Mat& grey, double t, TrackedFrame& f);
    // Uncertain when a weak (or feature) pose is far from the motion prediction.
    void guardPrediction(double t, const std::optional<Pose>& prior, TrackedFrame& f) const;
    // The ok pose's history, the temporal filter and the re-anchoring blend.
    void record(double t, TrackedFrame& f);

    // Image box of the board projected with T_world_camera, grown by the margins (or not), clipped
    // to the image; nullopt when a board corner is behind the camera.
    std::optional<cv::Rect> boardRegion(const Pose& T_world_camera, cv::Size image,
                                        bool withMargins) const;

    // The pose predicted for time t: constant velocity from the last two ok poses when both are
    // recent, else the last ok pose.
    Pose predictPose(double t) const;

    TrackerOptions options_;
    Detector detector_;
    // Coarse-to-fine search: the frame's tags from libapriltag on the decimated image (inside
    // `region`), then all board tags found from their pose; false (f unchanged but the coarse
    // fields) to fall back.
    bool coarseToFine(const cv::Mat& grey, const cv::Rect& region, float decimate,
                      const std::optional<Pose>& prior, TrackedFrame& f);

    // libapriltag's search of `region` at DetectorOptions::decimate, the pose, then the adaptive
    // full-resolution pass (TrackerOptions::fullResolutionFallback); fills the frame's
    // detections and estimate and adds to its timings. A non-empty retryWindow: when the
    // decimated search finds no tag, the coarse-to-fine search at full resolution in that window
    // comes before the full-resolution search of the region (TrackerOptions::windowRetry).
    void searchTags(const cv::Mat& grey, const cv::Rect& region, const cv::Rect& retryWindow,
                    const std::optional<Pose>& ambiguityPrior, double t, TrackedFrame& f);
    // The full-resolution pass's detector, created when first needed.
    Detector& fullResolutionDetector();
    // The decimations the coarse-first window is searched at, in turn, after the plan's
    // decimation found no tag there (TrackerOptions::coarseFirstCascade); none without a window.
    std::vector<float> coarseCascade(const SearchPlan& plan) const;

    // Fills TagDetection::edgeWidthPx of the board tags: the edge width (blur) around the
    // largest one, for the estimator's corner-noise model (~0.02-0.05 ms).
    void measureBlur(const cv::Mat& grey, std::vector<TagDetection>& dets) const;

    PredictedTagFinder tagFinder_;
    // The full-resolution pass's detector (adaptive detection), created when first needed.
    std::unique_ptr<Detector> fullResolutionDetector_;
    // Coarse detectors by decimation, created when first needed.
    std::vector<std::pair<float, std::unique_ptr<Detector>>> coarseDetectors_;
    int coarseCellsAtBorder_ = 8;
    // The board's largest tag side over its diameter (the largest distance between two tag
    // corners): the largest tag's image side per pixel of the board's image extent.
    double largestTagOverDiameter_ = 0;
    PoseEstimator estimator_;
    PoseFilter filter_;
    OneEuroPoseFilter oneEuro_;
    std::optional<Pose> lastOk_;
    double lastOkT_ = 0;
    bool lastOkWellDetermined_ = false;
    std::optional<Pose> previousOk_;  // the ok pose before lastOk_ (for the velocity)
    double previousOkT_ = 0;
    int framesSinceFullSearch_ = 0;
    std::unique_ptr<FeatureTracker> features_;
    TrackingMode lastMode_ = TrackingMode::Board;  // of the last ok frame
    std::array<double, 6> reanchorOffset_{};       // board pose -> drifted pose (poseDifference)
    int reanchorLeft_ = 0;                         // frames of the blend still to come
    // Times and camera centres (world, metres) of the ok poses from the board alone over the
    // last kBoardVelocityWindowS: the velocity the prior on a pose from features moves the last
    // centre by (poses from features would feed their own errors back into the velocity; a
    // window of several board poses averages their noise).
    static constexpr double kBoardVelocityWindowS = 0.25;
    std::deque<std::pair<double, glm::dvec3>> boardCentres_;
    // The board poses' velocity of the camera centre (m/s) over the window; zero without two.
    glm::dvec3 boardVelocity() const;
};

}  // namespace mirage::tracking
