#include "tracking/PoseFilter.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>

#include "core/math/Pose.h"

namespace mirage::tracking {
namespace {

double alpha(double cutoffHz, double dt) {
    const double tau = 1.0 / (2.0 * M_PI * cutoffHz);
    return 1.0 / (1.0 + tau / dt);
}

bool usable(const PoseCovariance* c) {
    if (!c) return false;
    bool any = false;
    for (double v : *c) {
        if (!std::isfinite(v)) return false;
        any = any || v != 0.0;
    }
    return any && (*c)[0] > 0 && (*c)[21] > 0;
}

}  // namespace

Pose PoseFilter::update(const Pose& measured, double t, const PoseCovariance* covariance) {
    if (!state_ || !(t > state_->t) || t - state_->t > options_.maxGapS || !measured.isFinite()) {
        state_ = State{measured, t, glm::dvec3(0.0), glm::dvec3(0.0)};
        lastGain_ = 1.0;
        return measured;
    }
    State& s = *state_;
    const double dt = t - s.t;
    // 1. Constant-velocity prediction.
    Pose pred = s.filtered;
    pred.rotation =
        glm::normalize(rotationFromVector(s.angularVelocity * dt) * s.filtered.rotation);
    pred.translation += s.velocity * dt;
    // 2. Innovation in the estimator's perturbation convention (world-frame rotation vector,
    // camera-centre offset).
    const glm::dvec3 eR = rotationVector(measured.rotation * glm::conjugate(pred.rotation));
    const glm::dvec3 eT = measured.translation - pred.translation;
    // 3. Normalised innovation with the measurement covariance (plus the floor on the diagonal).
    cv::Matx66d S = cv::Matx66d::zeros();
    if (usable(covariance)) {
        for (int a = 0; a < 6; ++a)
            for (int b = 0; b < 6; ++b) S(a, b) = (*covariance)[size_t(a * 6 + b)];
    } else {
        for (int a = 0; a < 3; ++a) {
            S(a, a) = options_.defaultRotationSigmaRad * options_.defaultRotationSigmaRad;
            S(a + 3, a + 3) = options_.defaultTranslationSigmaM * options_.defaultTranslationSigmaM;
        }
    }
    for (int a = 0; a < 3; ++a) {
        S(a, a) += options_.floorRotationSigmaRad * options_.floorRotationSigmaRad;
        S(a + 3, a + 3) += options_.floorTranslationSigmaM * options_.floorTranslationSigmaM;
    }
    cv::Vec6d e(eR.x, eR.y, eR.z, eT.x, eT.y, eT.z);
    const cv::Mat Sm(6, 6, CV_64F, S.val), em(6, 1, CV_64F, e.val);
    cv::Mat w;
    double m = 1e9;  // an unusable covariance: take the measurement as it is
    if (cv::solve(Sm, em, w, cv::DECOMP_CHOLESKY)) m = std::sqrt(std::max(0.0, em.dot(w)) / 6.0);
    // 4. Gain: minGain for a predictable pose, 1 for an unpredicted change, smoothstep between.
    const double r0 = options_.restInnovation, r1 = options_.motionInnovation;
    const double span = std::max(1e-9, r1 - r0);
    const double u = std::clamp((m - r0) / span, 0.0, 1.0);
    const double a = options_.minGain + (1.0 - options_.minGain) * u * u * (3.0 - 2.0 * u);
    const double b = std::min(options_.maxVelocityGain, a * a / (2.0 - a));
    // 5. Correct pose and velocity.
    s.filtered.rotation = glm::normalize(rotationFromVector(a * eR) * pred.rotation);
    s.filtered.translation = pred.translation + a * eT;
    s.angularVelocity += (b / dt) * eR;
    s.velocity += (b / dt) * eT;
    s.t = t;
    lastGain_ = a;
    return s.filtered;
}

Pose OneEuroPoseFilter::update(const Pose& measured, double t) {
    if (!state_ || !(t > state_->t) || !measured.isFinite()) {
        state_ = State{measured, t, glm::dvec3(0.0), glm::dvec3(0.0)};
        return measured;
    }
    State& s = *state_;
    const double dt = t - s.t;
    const glm::dvec3 dT = measured.translation - s.filtered.translation;
    const glm::dvec3 dR = rotationVector(glm::conjugate(s.filtered.rotation) * measured.rotation);
    const double aD = alpha(options_.derivativeCutoffHz, dt);
    // Low-pass the velocity vectors (as One Euro does per coordinate), then take their norms: at
    // rest the noise's velocities cancel instead of adding up as magnitudes would.
    s.velocityT += aD * (dT / dt - s.velocityT);
    s.velocityR += aD * (s.filtered.rotation * dR / dt - s.velocityR);  // world axes
    const double aT =
        alpha(options_.minCutoffHz + options_.translationBeta * glm::length(s.velocityT), dt);
    const double aR =
        alpha(options_.minCutoffHz + options_.rotationBeta * glm::length(s.velocityR), dt);
    s.filtered.translation += aT * dT;
    s.filtered.rotation = glm::normalize(s.filtered.rotation * rotationFromVector(aR * dR));
    s.t = t;
    return s.filtered;
}

}  // namespace mirage::tracking
