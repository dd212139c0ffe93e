#pragma once
// The main camera's exposure and white balance over time (docs/camera-matching.md): each frame
// the footage is measured against the renderer's expected radiance of the real surfaces (a
// RadiometricRatio of footage / L_r over well-exposed, unoccluded proxy pixels,
// render/passes/exposure), and this filter turns those measurements into the gain the
// compositor applies to everything the renderer adds.
//
// The gain is tracked per channel in log space (a white-balance shift is a per-channel gain, an
// exposure change the same factor in all three) by an alpha-beta filter: a level and a trend, so
// that a ramp (an auto-exposure settling over a few frames) is followed without a constant lag,
// while a frame's measurement noise is smoothed. A step is a step: a measurement further from the
// prediction than stepRatio in any channel is taken at once (level = measurement, trend 0), not
// smoothed towards over many frames. A frame without a usable measurement (black or saturated
// footage, hardly any real surface in view) keeps the last gain, or the prior before the first
// measurement, and says why. A camera that reports its exposure (time x gain, any unit) gives the
// prediction its change: the gain follows the report in frames without a measurement and a
// reported step is expected rather than detected.
#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "render/RadiometricRatio.h"

namespace mirage::render {

struct ExposureTrackerSettings {
    double smoothing = 0.6;   // alpha in (0, 1]: share of the residual the level takes (1: none)
    double trend = 0.25;      // beta in [0, 1): share of the residual the trend takes (0: none)
    double stepRatio = 1.12;  // > 1: a measurement off the prediction by more is a step
    int minSamples = 24;      // sample blocks needed for a measurement
    // Per channel: a measurement whose ratios spread more than this (half IQR over the median)
    // is not trusted (the model does not match the footage there: wrong proxies or lights).
    double maxSpread = 0.5;
    // Throws mirage::Error naming the first field out of range.
    void validate() const;
};

enum class ExposureSource {
    Prior,     // no measurement yet: the prior (RendererOptions::composite.exposure)
    Measured,  // this frame's measurement, smoothed
    Step,      // this frame's measurement taken at once: a step was detected
    Held,      // no usable measurement this frame: the last gain (times a reported change)
};
const char* exposureSourceName(ExposureSource s);  // "prior", "measured", "step", "held"

struct ExposureState {
    glm::dvec3 gain{1.0};  // rendered linear radiance -> camera linear units, per channel (R, G, B)
    ExposureSource source = ExposureSource::Prior;
    std::optional<RatioStatistics> measurement;  // this frame's, when usable
    std::string note;                            // why a frame held its gain, or the step's factor
};

class ExposureTracker {
public:
    explicit ExposureTracker(const glm::dvec3& prior = glm::dvec3(1.0),
                             ExposureTrackerSettings settings = {});

    // One frame: its ratios (footage / expected radiance; their statistics are taken with
    // settings.minSamples), `whyNone` saying why there are too few when so (for the note), and
    // the camera's own exposure report if it gives one (> 0, any unit; its changes count).
    const ExposureState& update(const RadiometricRatio& ratios, const std::string& whyNone = {},
                                std::optional<double> reportedExposure = std::nullopt);
    const ExposureState& state() const { return state_; }
    // Back to the prior, as before the first frame.
    void reset();
    void setPrior(const glm::dvec3& prior);

private:
    void hold(const std::string& why, double reportedLogChange);

    glm::dvec3 prior_;
    ExposureTrackerSettings settings_;
    ExposureState state_;
    bool measured_ = false;               // some frame gave a measurement since the last reset
    glm::dvec3 level_{0.0}, trend_{0.0};  // log gain per channel and its change per frame
    std::optional<double> lastReport_;
};

}  // namespace mirage::render
