#pragma once
// The one estimator of a radiometric ratio between two measurements of the same radiance, per
// channel: the environment camera against the main camera (render/EnvironmentRadiometry.h) and
// the footage against the renderer's expected radiance of the real surfaces, each frame (the
// exposure and white balance, render/ExposureTracker.h, render/passes/exposure). Each pair gives
// ratio = measured / reference per channel (R, G, B, linear); the estimate is the per-channel
// median, robust to the pairs a pose error, an occluder the model lacks or a specular highlight
// spoil, and its spread is half the interquartile range over the median.
//
// Which pairs are worth adding is the same rule for both users: a measured 8-bit camera value is
// a measurement only between kWellExposedLowCode and kWellExposedHighCode (below, quantisation
// and noise dominate; above, the sensor or the encoding clips: the value is "at least", not a
// measurement).
#include <optional>
#include <vector>

#include <glm/glm.hpp>

namespace mirage::render {

// 8-bit sRGB codes that count as well exposed, inclusive.
inline constexpr int kWellExposedLowCode = 16, kWellExposedHighCode = 239;
bool wellExposedCode(int code);
// The same bounds as linear values (sRGB-decoded codes): what a linear measurement (a mean of
// well-exposed pixels, say) is checked against.
double wellExposedLowLinear();
double wellExposedHighLinear();
// True when every channel of a linear RGB value lies within the well-exposed bounds.
bool wellExposedLinear(const glm::dvec3& linearRgb);

struct RatioStatistics {
    glm::dvec3 ratio{1.0};   // per-channel median of measured / reference
    glm::dvec3 spread{0.0};  // per channel: half the interquartile range over the median
    int samples = 0;         // pairs used
};

class RadiometricRatio {
public:
    // One pair of linear RGB values of the same radiance. Returns false, adding nothing, unless
    // every channel of both is finite and positive (a zero reference has no ratio).
    bool add(const glm::dvec3& measured, const glm::dvec3& reference);
    void clear() { ratios_.clear(); }
    int size() const { return int(ratios_.size()); }
    // nullopt below max(minSamples, 1) pairs.
    std::optional<RatioStatistics> statistics(int minSamples) const;

private:
    std::vector<glm::dvec3> ratios_;
};

}  // namespace mirage::render
