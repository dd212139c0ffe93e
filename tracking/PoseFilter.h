#pragma once
// Temporal filter of camera poses: the One Euro filter (Casiez, Roussel, Vogel, CHI 2012) on
// translation and on rotation. A low-pass whose cutoff rises with speed: at rest the cutoff is
// minCutoffHz (jitter removed), in fast motion it is minCutoff + beta * speed, which bounds the
// lag to about 1 / (2 pi beta) in metres (translation) or radians (rotation) however fast.
//
// Rotation is filtered on the manifold: the step from the previous filtered orientation to the
// new one is delta = log(q_prev^-1 q_new) (a rotation vector in the filtered body frame), and
// q_filtered = q_prev exp(alpha * delta), with the speed |delta| / dt driving the cutoff.
#include <optional>

#include "core/math/Pose.h"

namespace mirage::tracking {

struct OneEuroOptions {
    double minCutoffHz = 0.5;         // cutoff at rest (translation and rotation)
    double translationBeta = 20.0;    // 1/m: cutoff grows by beta Hz per m/s of speed
    double rotationBeta = 20.0;       // 1/rad: cutoff grows by beta Hz per rad/s
    double derivativeCutoffHz = 1.0;  // low-pass of the speed estimate
};

class PoseFilter {
public:
    explicit PoseFilter(OneEuroOptions options = {}) : options_(options) {}

    // Filters the pose measured at time t (seconds, increasing). The first call after
    // construction or reset() returns the measurement itself. A non-increasing t resets.
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
