#pragma once
// Constant-velocity prediction of a camera pose T_world_camera to a later time: the live loop
// renders a frame with the pose its camera will have when the frame is displayed, not the one
// it had when the frame was captured (docs/live.md, "Pose prediction").
//
// The velocity is a twist in the camera's own frame (OpenCV camera axes), taken from the last
// two poses: the motion between them, T_prev^-1 T_last = exp(dt [w, v]), divided by their time
// difference. Moving on with the same twist is a screw motion, so a straight pan, a turn in
// place and an orbit about a point at a constant rate are all predicted exactly (a constant
// world-frame velocity of the camera centre would cut an orbit's arc short).
#include <optional>

#include <glm/glm.hpp>

#include "core/math/Pose.h"

namespace mirage::tracking {

// Velocity of a camera in its own frame (OpenCV axes): turning rate `angular` (rad/s, about
// the camera's axes) and `linear` (m/s, along them), the se(3) twist of T_world_camera.
struct PoseVelocity {
    glm::dvec3 angular{0.0};
    glm::dvec3 linear{0.0};
};

// The twist that takes `from` to `to` in `seconds` (> 0): log(from^-1 to) / seconds.
PoseVelocity velocityBetween(const Pose& from, const Pose& to, double seconds);
// `pose` moved on with `velocity` for `seconds` (negative: back): pose exp(seconds [w, v]).
Pose extrapolatePose(const Pose& pose, const PoseVelocity& velocity, double seconds);

struct PosePredictorOptions {
    // Two poses further apart than this give no velocity (seconds): over a longer gap the
    // motion has likely changed (the tracker's filter restarts after the same gap).
    double maxGapS = 0.5;
    // Predictions are made at most this far past the last pose (seconds): a horizon beyond
    // it is cut to it (a hand's motion does not stay constant for longer).
    double maxAheadS = 0.5;
    // Two poses implying a faster motion give no velocity (m/s of the camera centre, rad/s of
    // turn): a jump, not a motion (a tracking glitch, a recorded stand-in starting again), whose
    // extrapolation would throw the pose far off.
    double maxSpeedMps = 3.0;
    double maxTurnRadps = 6.0;
};

class PosePredictor {
public:
    explicit PosePredictor(PosePredictorOptions options = {}) : options_(options) {}

    // A pose measured at time `t` (seconds, increasing). A non-increasing time, a gap longer
    // than maxGapS, a jump (faster than maxSpeedMps or maxTurnRadps) or a non-finite pose starts
    // again from this pose (no velocity yet).
    void update(const Pose& T_world_camera, double t);
    // Forgets every pose (tracking was lost: the next pose starts afresh).
    void reset();

    // The velocity from the last two poses; nullopt before two poses.
    const std::optional<PoseVelocity>& velocity() const { return velocity_; }
    // The last pose moved on to time `t` with the velocity (the horizon t - its time cut to
    // [0, maxAheadS]); the last pose itself without a velocity; nullopt before any pose.
    std::optional<Pose> predict(double t) const;
    // The horizon predict(t) uses: t - the last pose's time, cut to [0, maxAheadS] (seconds).
    double horizon(double t) const;

    const PosePredictorOptions& options() const { return options_; }

private:
    PosePredictorOptions options_;
    std::optional<Pose> last_;
    double lastT_ = 0;
    std::optional<PoseVelocity> velocity_;
};

}  // namespace mirage::tracking
