#pragma once
// Camera pose from the tags of a board seen in one frame (docs/tracking.md, "Pose").
//
// Per tag: detection corners unprojected with the camera model (Brown-Conrady or Kannala-Brandt),
// IPPE on the square tag (cv::solvePnPGeneric, SOLVEPNP_IPPE_SQUARE) gives two candidate poses.
// Candidates are scored on all tags, the best few refined by Levenberg-Marquardt on the pixel
// reprojection error of all corners of the inlier tags, tags that do not fit are rejected, and the
// planar two-fold ambiguity is resolved by the ratio of the reprojection errors of the best pose
// and the best distinct alternative, or else by closeness to the previous pose. If neither
// settles it, the state is `ambiguous`, never `ok`.
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "core/camera/CameraModel.h"
#include "core/math/LevenbergMarquardt.h"
#include "core/math/Pose.h"
#include "tracking/Board.h"
#include "tracking/Detector.h"

namespace mirage::tracking {

enum class TrackingState { Ok, NoTags, TagsTooSmall, TooBlurred, Ambiguous, Lost, Uncertain };
// "ok", "no_tags", "tags_too_small", "too_blurred", "ambiguous", "lost", "uncertain" (the CSV
// spelling). Uncertain: a pose was found but its covariance exceeds what ok promises (or it is
// far from the motion prediction with a weak fit); it is reported, never used as tracking output.
const char* trackingStateName(TrackingState s);

struct PoseEstimatorOptions {
    // Tags whose shortest side is below this (pixels) are not used: their corners are too
    // imprecise for a trustworthy pose. If all tags are that small: state tags_too_small.
    double minTagSidePx = 10.0;
    // Candidate scoring: a tag supports a candidate pose if its corners reproject within
    // max(candidateInlierPx, 15 % of its side).
    double candidateInlierPx = 4.0;
    // After refinement a tag is an outlier if its corner RMS exceeds
    // max(outlierTagRmsPx, 4 x the median tag RMS); it is dropped and the pose refined again.
    double outlierTagRmsPx = 1.5;
    // The final RMS over all used corners must be below this, else state lost.
    double maxRmsPx = 2.0;
    // Planar ambiguity: the alternative pose must reproject at least this many times worse
    // (RMS ratio) AND by at least ambiguityMinGapPx more, else the frame is ambiguous...
    double ambiguityRatio = 2.0;
    double ambiguityMinGapPx = 0.3;
    // ...unless a previous pose decides (the Tracker passes one only when it was well
    // determined and recent): the chosen pose must be within priorMaxRotationDeg of it and the
    // alternative at least twice as far from it as the chosen one.
    double priorMaxRotationDeg = 15.0;
    // Uncertainty (docs/tracking.md, "Uncertainty and the ok state"). The pose covariance is
    //   C = k^2 N^-1 (sigma^2 N + sigma^2 (a^2 - 1) H_tag / 4
    //                 + sigma0^2 (t^2 S_tag + h^2 H_tag + c^2 g g^T)) N^-1,   N = J^T J:
    // independent corner noise sigma (per image coordinate), except that the centre of each tag
    // (the mean of its 4 corners) errs less, a^2 of the variance independent noise gives it
    // (a = tagCentreNoise; H_tag / 4 is the shift mode of the tags' corners), plus corner errors
    // shared by the corners of a tag (a scale change of each tag, t; a shift of each tag, h; a
    // scale change common to all tags of the frame, c; as multiples of sigma0). sigma^2 pools
    // the residuals' robust mean square (median absolute residual) with a prior of w degrees of
    // freedom:
    //   sigma^2 = (2N rho^2 + w sigma0^2) / (2N - 6 + w),
    // sigma0 = cornerNoisePx + cornerNoiseSidePx / (shortest tag side in pixels)
    //          + cornerNoiseBlur * max(0, edge width - 2.2 px)^2 (TagDetection::edgeWidthPx, when
    // measured), averaged in variance over the used tags: small tags have noisier corners
    // (fewer edge samples; blur and compression move a larger share of them), and a blur wider
    // than a cell mixes the payload bits into the border edges. With one tag (2 degrees of
    // freedom left) the residuals alone can claim almost any precision; the prior keeps the
    // claim honest. With many tags the pose rests on the tags' centres, which the independent
    // noise alone overstates. All constants measured by Monte Carlo (tracking_montecarlo).
    double cornerNoisePx = 0.05;
    double cornerNoiseSidePx = 1.2;
    double cornerNoiseBlur = 0.12;  // 1 / pixel
    double cornerNoisePriorWeight = 8.0;
    double covarianceInflation = 1.0;  // k0
    // k_b: k = k0 (1 + k_b x mean edge width beyond 2.2 px) (1 / pixel).
    double covarianceBlurInflation = 0.1;
    // t, h, c above (pixels per pixel of sigma0).
    double tagScaleNoise = 0.4;
    double tagShiftNoise = 0.1;
    double commonScaleNoise = 0.65;
    // a above: the tag centre's standard deviation as a fraction of what independent corner
    // noise gives it (1: independent corners).
    double tagCentreNoise = 0.75;
    // A pose is ok only when the square roots of the covariance traces (1 sigma, 3D) are at most
    // okMaxSigmaRotDeg (degrees) and okMaxSigmaPosFraction of the camera-to-tags distance; a
    // pose beyond either is `uncertain`. With an honest covariance a pose off by 2 degrees or 2 %
    // (wrong) is then at least 4 sigma out.
    double okMaxSigmaRotDeg = 0.5;
    double okMaxSigmaPosFraction = 0.005;
    // Corners of fish-eye rays more than this far off the optical axis are not used for the IPPE
    // initialisation (normalised coordinates explode near 90 degrees); LM still uses them.
    double maxInitAngleDeg = 75.0;
    // Initial candidates come from the IPPE solutions of this many tags, the largest in the
    // image (all tags still score them and enter the refinement).
    int maxInitTags = 6;
};

struct PoseEstimate {
    TrackingState state = TrackingState::NoTags;
    std::string reason;             // human-readable why (also for ok: what was used)
    std::optional<Pose> pose;       // T_world_camera; set when state is ok (and for ambiguous, the
                                    // lower-error guess, which must not be used as tracking output)
    std::vector<int> tagsUsed;      // board tag ids in the final fit
    std::vector<int> tagsRejected;  // ids detected but rejected as outliers or too small
    // ids that disagree with the pose of the others (a subset of tagsRejected). When they are
    // not fewer than the tags used, the state is lost and the reason asks about the board file.
    std::vector<int> tagsDisagreeing;
    double distanceM = 0;          // camera centre to the centre of the used tags (metres)
    double rmsPx = -1;             // reprojection RMS over the used corners (pixels)
    double alternativeRmsPx = -1;  // RMS of the best distinct alternative pose (-1: none)
    // 6x6 covariance (row-major) of (rotation vector of a world-frame perturbation of the
    // camera's orientation, radians; camera centre in the world, metres): J^T J inverse scaled by
    // the residual variance. All zero when not computed.
    std::array<double, 36> covariance{};
    // Square roots of the covariance traces: rotation (degrees) and camera centre (metres).
    double sigmaRotDeg() const {
        return glm::degrees(
            std::sqrt(std::max(0.0, covariance[0] + covariance[7] + covariance[14])));
    }
    double sigmaPosM() const {
        return std::sqrt(std::max(0.0, covariance[21] + covariance[28] + covariance[35]));
    }
    // Many tags, or a small rotation uncertainty: the pose may decide the planar ambiguity of
    // later frames and stands against a surprising next pose (Tracker).
    bool wellDetermined(int minTags = 3, double maxSigmaRotDeg = 0.2) const {
        return state == TrackingState::Ok &&
               (int(tagsUsed.size()) >= minTags || sigmaRotDeg() <= maxSigmaRotDeg);
    }
};

class PoseEstimator {
public:
    PoseEstimator(Board board, CameraIntrinsics camera, PoseEstimatorOptions options = {});

    // detections: all tags found in the frame (ids not on the board are ignored).
    // prior: a previous T_world_camera, recent and well determined (it may decide the planar
    // ambiguity; the Tracker passes none otherwise).
    // initial: a pose expected to be close (the tracking mode's prediction, whose tags were
    // verified where it put them). It becomes the first candidate and only the largest tag's
    // IPPE solutions are added (for the planar flip of the ambiguity check) instead of those of
    // maxInitTags tags; outlier rejection and the ambiguity check are unchanged.
    PoseEstimate estimate(const std::vector<TagDetection>& detections,
                          const std::optional<Pose>& prior = std::nullopt,
                          const std::optional<Pose>& initial = std::nullopt) const;

    const Board& board() const { return board_; }
    const CameraIntrinsics& camera() const { return camera_; }
    const PoseEstimatorOptions& options() const { return options_; }

private:
    Board board_;
    CameraIntrinsics camera_;
    PoseEstimatorOptions options_;
};

// The refinement's least-squares problem (core/math/LevenbergMarquardt.h) over all corners of the
// board tags in `detections` (a tag id seen twice is left out): residuals = projected - detected
// pixels, x then y per corner; state = poseState(T_world_camera) = (camera centre in the world,
// metres; orientation quaternion w x y z); step = (rotation vector of a world-frame perturbation of
// the orientation, radians; camera-centre offset, metres). The problem keeps copies of its inputs.
lm::Problem poseLeastSquares(const Board& board, const CameraIntrinsics& camera,
                             const std::vector<TagDetection>& detections);
std::vector<double> poseState(const Pose& T_world_camera);
Pose poseOfState(const std::vector<double>& x);

}  // namespace mirage::tracking
