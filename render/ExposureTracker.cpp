#include "render/ExposureTracker.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/Error.h"

namespace mirage::render {
namespace {

// Gains outside this range are not a camera's exposure but a broken model or footage.
constexpr double kMinGain = 1e-4, kMaxGain = 1e4;

glm::dvec3 logOf(const glm::dvec3& v) {
    return {std::log(v.x), std::log(v.y), std::log(v.z)};
}
glm::dvec3 expOf(const glm::dvec3& v) {
    return {std::exp(v.x), std::exp(v.y), std::exp(v.z)};
}

}  // namespace

void ExposureTrackerSettings::validate() const {
    if (!(smoothing > 0.0 && smoothing <= 1.0))
        throw Error("exposure tracker: smoothing must be in (0, 1]");
    if (!(trend >= 0.0 && trend < 1.0)) throw Error("exposure tracker: trend must be in [0, 1)");
    if (!(stepRatio > 1.0 && std::isfinite(stepRatio)))
        throw Error("exposure tracker: stepRatio must be a finite number above 1");
    if (minSamples < 1) throw Error("exposure tracker: minSamples must be at least 1");
    if (!(maxSpread > 0.0)) throw Error("exposure tracker: maxSpread must be positive");
}

const char* exposureSourceName(ExposureSource s) {
    switch (s) {
        case ExposureSource::Prior:
            return "prior";
        case ExposureSource::Measured:
            return "measured";
        case ExposureSource::Step:
            return "step";
        case ExposureSource::Held:
            return "held";
    }
    return "?";
}

ExposureTracker::ExposureTracker(const glm::dvec3& prior, ExposureTrackerSettings settings)
    : settings_(settings) {
    settings_.validate();
    setPrior(prior);
}

void ExposureTracker::setPrior(const glm::dvec3& prior) {
    for (int c = 0; c < 3; ++c)
        if (!(prior[c] >= kMinGain && prior[c] <= kMaxGain))
            throw Error(fmt::format("exposure tracker: the prior gain must be in [{}, {}]",
                                    kMinGain, kMaxGain));
    prior_ = prior;
    if (!measured_) reset();
}

void ExposureTracker::reset() {
    measured_ = false;
    level_ = logOf(prior_);
    trend_ = glm::dvec3(0.0);
    lastReport_.reset();
    state_ = ExposureState{};
    state_.gain = prior_;
    state_.source = ExposureSource::Prior;
}

void ExposureTracker::hold(const std::string& why, double reportedLogChange) {
    // Without a measurement the trend is not extrapolated (a ramp that ended would run on), but
    // a change the camera reports is followed.
    trend_ = glm::dvec3(0.0);
    level_ += glm::dvec3(reportedLogChange);
    level_ = glm::clamp(level_, glm::dvec3(std::log(kMinGain)), glm::dvec3(std::log(kMaxGain)));
    state_.gain = expOf(level_);
    state_.source = measured_ ? ExposureSource::Held : ExposureSource::Prior;
    state_.note = (measured_ ? "kept the last estimate: " : "kept the prior: ") + why;
}

const ExposureState& ExposureTracker::update(const RadiometricRatio& ratios,
                                             const std::string& whyNone,
                                             std::optional<double> reportedExposure) {
    double reportedLogChange = 0.0;
    if (reportedExposure && std::isfinite(*reportedExposure) && *reportedExposure > 0.0) {
        if (lastReport_) reportedLogChange = std::log(*reportedExposure / *lastReport_);
        lastReport_ = reportedExposure;
    }
    state_.measurement = ratios.statistics(settings_.minSamples);
    state_.note.clear();
    if (!state_.measurement) {
        hold(whyNone.empty() ? fmt::format("{} usable sample(s), {} needed", ratios.size(),
                                           settings_.minSamples)
                             : whyNone,
             reportedLogChange);
        return state_;
    }
    const RatioStatistics& m = *state_.measurement;
    for (int c = 0; c < 3; ++c) {
        if (!(m.ratio[c] >= kMinGain && m.ratio[c] <= kMaxGain)) {
            state_.measurement.reset();
            hold(fmt::format("the measured gain {:.3g} is outside [{}, {}]: the footage does not "
                             "match the model",
                             m.ratio[c], kMinGain, kMaxGain),
                 reportedLogChange);
            return state_;
        }
        if (!(m.spread[c] <= settings_.maxSpread)) {
            state_.measurement.reset();
            hold(fmt::format("the footage / model ratios spread by {:.0f} % (at most {:.0f} % "
                             "trusted): the proxies or lights do not match the footage",
                             100.0 * m.spread[c], 100.0 * settings_.maxSpread),
                 reportedLogChange);
            return state_;
        }
    }
    const glm::dvec3 measured = logOf(m.ratio);
    if (!measured_) {  // the first measurement: nothing to smooth towards
        measured_ = true;
        level_ = measured;
        trend_ = glm::dvec3(0.0);
        state_.gain = m.ratio;
        state_.source = ExposureSource::Measured;
        state_.note = "first measurement";
        return state_;
    }
    const glm::dvec3 predicted = level_ + trend_ + glm::dvec3(reportedLogChange);
    const glm::dvec3 residual = measured - predicted;
    const double worst =
        std::max({std::abs(residual.x), std::abs(residual.y), std::abs(residual.z)});
    if (worst > std::log(settings_.stepRatio)) {
        level_ = measured;
        trend_ = glm::dvec3(0.0);
        state_.source = ExposureSource::Step;
        const glm::dvec3 factor = expOf(residual);
        state_.note = fmt::format("step of x{:.3f} {:.3f} {:.3f} (R G B) from the prediction",
                                  factor.x, factor.y, factor.z);
    } else {
        level_ = predicted + settings_.smoothing * residual;
        trend_ += settings_.trend * residual;
        state_.source = ExposureSource::Measured;
    }
    level_ = glm::clamp(level_, glm::dvec3(std::log(kMinGain)), glm::dvec3(std::log(kMaxGain)));
    state_.gain = expOf(level_);
    return state_;
}

}  // namespace mirage::render
