#include "render/RadiometricRatio.h"

#include <algorithm>
#include <cmath>

#include "core/image/ImageIO.h"

namespace mirage::render {
namespace {

double quantile(std::vector<double> v, double q) {
    const size_t k = std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5));
    std::nth_element(v.begin(), v.begin() + long(k), v.end());
    return v[k];
}

bool finitePositive(const glm::dvec3& v) {
    for (int c = 0; c < 3; ++c)
        if (!std::isfinite(v[c]) || v[c] <= 0.0) return false;
    return true;
}

}  // namespace

bool wellExposedCode(int code) {
    return code >= kWellExposedLowCode && code <= kWellExposedHighCode;
}

double wellExposedLowLinear() {
    static const double v = srgbToLinear(float(kWellExposedLowCode) / 255.0f);
    return v;
}

double wellExposedHighLinear() {
    static const double v = srgbToLinear(float(kWellExposedHighCode) / 255.0f);
    return v;
}

bool wellExposedLinear(const glm::dvec3& v) {
    for (int c = 0; c < 3; ++c)
        if (!(v[c] >= wellExposedLowLinear() && v[c] <= wellExposedHighLinear())) return false;
    return true;
}

bool RadiometricRatio::add(const glm::dvec3& measured, const glm::dvec3& reference) {
    if (!finitePositive(measured) || !finitePositive(reference)) return false;
    const glm::dvec3 r = measured / reference;
    if (!finitePositive(r)) return false;  // overflow of a tiny reference
    ratios_.push_back(r);
    return true;
}

std::optional<RatioStatistics> RadiometricRatio::statistics(int minSamples) const {
    if (ratios_.empty() || int(ratios_.size()) < std::max(minSamples, 1)) return std::nullopt;
    RatioStatistics s;
    s.samples = int(ratios_.size());
    std::vector<double> v(ratios_.size());
    for (int c = 0; c < 3; ++c) {
        for (size_t i = 0; i < ratios_.size(); ++i) v[i] = ratios_[i][c];
        s.ratio[c] = quantile(v, 0.5);
        s.spread[c] = 0.5 * (quantile(v, 0.75) - quantile(v, 0.25)) / s.ratio[c];
    }
    return s;
}

}  // namespace mirage::render
