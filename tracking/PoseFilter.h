#pragma once
// Temporal filters of camera poses T_world_camera (docs/tracking.md, "Temporal filter").
//
// PoseFilter (the default): a constant-velocity predictive filter whose gain adapts to how well
// the prediction explains the new measurement, judged with the measurement's own covariance (the
// pose estimator's 6x6 covariance per frame). Per frame:
//   1. predict: the previous filtered pose moved on by the filtered velocity for dt (rotation on
//      the manifold, q_pred = exp(omega dt) q);
//   2. innovation e = (log(q_meas q_pred^-1), p_meas - p_pred): world-frame rotation vector
//      (radians) and camera-centre offset (metres), the estimator's perturbation convention;
//   3. m = sqrt(e^T Sigma^-1 e / 6), the innovation in measurement standard deviations per degree
//      of freedom (about 1 when the prediction is right and only noise is left);
//   4. gain alpha = minGain while m <= restInnovation, rising smoothly to 1 at
//      motionInnovation: a predictable pose (at rest, or moving at constant velocity) is
//      smoothed hard, an unpredicted change (a start, stop or turn) passes through at once;
//   5. pose = pred + alpha e, velocity += beta e / dt with beta = alpha^2 / (2 - alpha) (the
//      critically damped alpha-beta pair) but at most maxVelocityGain: a single noisy frame must
//      not set the velocity (with beta = 1 the velocity would be the difference of two noisy
//      poses, and the next predictions would miss by that noise, keeping the gain open).
// Because the gain opens as soon as the prediction misses by a few measurement sigmas, the lag
// during accelerations is bounded by a few sigmas of the measurement noise (not by a speed
// constant as in One Euro); in hand-held motion the filter mostly passes the measurements
// through, at rest it averages them.
// One gain serves rotation and translation together: their errors are correlated (a small
// rotation and a translation of the camera can explain the corners almost equally), and filtering
// them with different gains would break that consistency.
//
// OneEuroPoseFilter: the previous default (Casiez, Roussel, Vogel, CHI 2012), a low-pass whose
// cutoff rises with speed; it lags by about 1 / (2 pi beta) in fast motion. Kept for comparison
// (`TrackerOptions::filterKind`, `mirage track --filter one-euro`).
#include <array>
#include <optional>

#include "core/math/Pose.h"

namespace mirage::tracking {

// 6x6 row-major covariance of (world-frame rotation vector, radians; camera centre, metres), as
// PoseEstimate::covariance. All zero = unknown.
using PoseCovariance = std::array<double, 36>;

struct PoseFilterOptions {
    // Gain when the constant-velocity prediction explains the measurement (at rest or uniform
    // motion): 0.12 reduces white measurement noise about 3.3x in standard deviation.
    double minGain = 0.1;
    // Normalised innovation m (sigmas per degree of freedom; ~1 for pure measurement noise, and
    // m > 2 has a probability under 1 % then) up to which minGain is used, and
    // from which the measurement is taken as it is (gain 1). Between: smoothstep.
    double restInnovation = 2.0;
    double motionInnovation = 4.0;
    // Upper limit of the velocity gain beta (see 5. above).
    double maxVelocityGain = 0.3;
    // Used when a measurement comes without covariance: per-axis standard deviations.
    double defaultRotationSigmaRad = 0.0005;   // 0.03 degree
    double defaultTranslationSigmaM = 0.0003;  // 0.3 mm
    // Added (in quadrature) to every measurement's standard deviations, per axis: keeps the
    // normalisation finite and does not let an over-confident covariance switch smoothing off.
    double floorRotationSigmaRad = 0.00005;   // 0.003 degree
    double floorTranslationSigmaM = 0.00002;  // 0.02 mm
    // A gap longer than this between two measurements restarts the filter (seconds).
    double maxGapS = 0.5;
};

class PoseFilter {
public:
    explicit PoseFilter(PoseFilterOptions options = {}) : options_(options) {}

    // Filters the pose measured at time t (seconds, increasing). covariance: the measurement's
    // (PoseEstimate::covariance); nullptr or all zero = the default sigmas. The first call after
    // construction or reset() returns the measurement itself. A non-increasing t, a gap over
    // maxGapS or a non-finite pose restarts.
    Pose update(const Pose& measured, double t, const PoseCovariance* covariance = nullptr);
    void reset() { state_.reset(); }
    bool active() const { return state_.has_value(); }
    // Gain used by the last update (1 after a restart), for diagnostics and tests.
    double lastGain() const { return lastGain_; }

    const PoseFilterOptions& options() const { return options_; }

private:
    struct State {
        Pose filtered;
        double t = 0;
        glm::dvec3 velocity{0.0};         // m/s, world axes
        glm::dvec3 angularVelocity{0.0};  // rad/s, world axes (q' = exp(omega dt) q)
    };
    PoseFilterOptions options_;
    std::optional<State> state_;
    double lastGain_ = 1.0;
};

struct OneEuroOptions {
    double minCutoffHz = 0.5;         // cutoff at rest (translation and rotation)
    double translationBeta = 20.0;    // 1/m: cutoff grows by beta Hz per m/s of speed
    double rotationBeta = 20.0;       // 1/rad: cutoff grows by beta Hz per rad/s
    double derivativeCutoffHz = 1.0;  // low-pass of the speed estimate
};

// One Euro filter on translation and on rotation (on the manifold: the step
// log(q_prev^-1 q_new) is scaled by the filter's alpha and applied with exp).
class OneEuroPoseFilter {
public:
    explicit OneEuroPoseFilter(OneEuroOptions options = {}) : options_(options) {}

    Pose update(const Pose& measured, double t);
    void reset() { state_.reset(); }
    bool active() const { return state_.has_value(); }

private:
    struct State {
        Pose filtered;
        double t = 0;
        glm::dvec3 velocityT{0.0};  // low-passed velocity (m/s, world axes)
        glm::dvec3 velocityR{0.0};  // low-passed angular velocity (rad/s, world axes)
    };
    OneEuroOptions options_;
    std::optional<State> state_;
};

}  // namespace mirage::tracking
