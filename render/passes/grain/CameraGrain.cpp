#include "render/passes/grain/CameraGrain.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/image/ImageIO.h"

namespace mirage::render {
namespace {

double median(std::vector<double> v) {
    const size_t m = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + long(m), v.end());
    if (v.size() % 2 == 1) return v[m];
    const double hi = v[m];
    return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + long(m)));
}

int levelOf(float linear) {
    const float encoded = linearToSrgb(std::clamp(linear, 0.0f, 1.0f));
    return std::clamp(int(encoded * float(kNoiseLevels)), 0, kNoiseLevels - 1);
}

// Solves the 3 x 3 normal equations of ratio = x0 + x1 r2 + x2 r2^2 over `use`d samples.
bool solveQuadratic(const std::vector<VignetteSample>& s, const std::vector<bool>& use,
                    glm::dvec3& x) {
    glm::dmat3 a(0.0);
    glm::dvec3 b(0.0);
    for (size_t i = 0; i < s.size(); ++i) {
        if (!use[i]) continue;
        const double r2 = s[i].r2;
        const glm::dvec3 basis(1.0, r2, r2 * r2);
        a += glm::outerProduct(basis, basis);
        b += basis * double(s[i].ratio);
    }
    if (std::abs(glm::determinant(a)) < 1e-12) return false;
    x = glm::inverse(a) * b;
    return std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z);
}

}  // namespace

float vignetteRadius2(const CameraIntrinsics& c, glm::vec2 q) {
    const double w = c.width - 1, h = c.height - 1;
    const double dx = std::max(c.cx, w - c.cx), dy = std::max(c.cy, h - c.cy);
    const double ex = q.x - c.cx, ey = q.y - c.cy;
    return float((ex * ex + ey * ey) / std::max(dx * dx + dy * dy, 1.0));
}

float NoiseLevelFunction::levelValue(int i) {
    return srgbToLinear((float(i) + 0.5f) / float(kNoiseLevels));
}

glm::vec3 NoiseLevelFunction::varianceAt(const glm::vec3& linear) const {
    glm::vec3 out;
    for (int c = 0; c < 3; ++c) {
        const float s =
            linearToSrgb(std::clamp(linear[c], 0.0f, 1.0f)) * float(kNoiseLevels) - 0.5f;
        const int i0 = std::clamp(int(std::floor(s)), 0, kNoiseLevels - 1);
        const int i1 = std::min(i0 + 1, kNoiseLevels - 1);
        const float t = std::clamp(s - float(i0), 0.0f, 1.0f);
        out[c] = variance[size_t(i0)][c] * (1.0f - t) + variance[size_t(i1)][c] * t;
    }
    return out;
}

std::optional<NoiseLevelFunction> estimateNoiseLevels(const std::vector<NoiseBlock>& blocks,
                                                      int minBlocksPerLevel, std::string& why) {
    NoiseLevelFunction f;
    std::vector<double> correlations;
    int measuredLevels = 0;
    for (int c = 0; c < 3; ++c) {
        std::array<std::vector<double>, kNoiseLevels> variances, values;
        for (const NoiseBlock& b : blocks) {
            if (!(b.variance[c] >= 0.0f) || !std::isfinite(b.variance[c])) continue;
            const int l = levelOf(b.mean[c]);
            variances[size_t(l)].push_back(b.variance[c]);
            values[size_t(l)].push_back(b.mean[c]);
        }
        // The measured levels, and the line variance = a + b value through them (least squares).
        std::array<bool, kNoiseLevels> measured{};
        double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
        for (int l = 0; l < kNoiseLevels; ++l) {
            if (int(variances[size_t(l)].size()) < minBlocksPerLevel) continue;
            measured[size_t(l)] = true;
            ++measuredLevels;
            const double v = median(variances[size_t(l)]), x = median(values[size_t(l)]);
            f.variance[size_t(l)][c] = float(v);
            sw += 1;
            sx += x;
            sy += v;
            sxx += x * x;
            sxy += x * v;
        }
        if (sw == 0) continue;
        double slope = 0.0, offset = sy / sw;
        const double det = sw * sxx - sx * sx;
        if (sw >= 2 && det > 1e-12) {
            slope = std::max(0.0, (sw * sxy - sx * sy) / det);
            offset = std::max(0.0, (sy - slope * sx) / sw);
        }
        for (int l = 0; l < kNoiseLevels; ++l)
            if (!measured[size_t(l)])
                f.variance[size_t(l)][c] =
                    float(offset + slope * double(NoiseLevelFunction::levelValue(l)));
    }
    for (const NoiseBlock& b : blocks)
        if (std::isfinite(b.correlation)) correlations.push_back(b.correlation);
    if (measuredLevels == 0) {
        why = fmt::format(
            "no intensity level has {} usable blocks ({} blocks show a smooth, unclipped real "
            "surface)",
            minBlocksPerLevel, blocks.size());
        return std::nullopt;
    }
    // Neighbouring pixels' correlation: the median over the blocks; below 0.1 it is taken for
    // white noise (the residual of the model's own shading error is correlated too).
    const double rho = correlations.empty() ? 0.0 : median(correlations);
    f.correlation = rho < 0.1 ? 0.0f : float(std::min(rho, 0.45));
    f.blocks = int(blocks.size());
    why = fmt::format("{} blocks, {} of {} channel levels measured", blocks.size(), measuredLevels,
                      3 * kNoiseLevels);
    return f;
}

std::optional<VignetteProfile> fitVignette(const std::vector<VignetteSample>& samples,
                                           int minSamples, float minRadius, std::string& why) {
    std::vector<bool> use(samples.size(), true);
    float maxR2 = 0.0f;
    int valid = 0;
    for (size_t i = 0; i < samples.size(); ++i) {
        use[i] = samples[i].ratio > 0.0f && std::isfinite(samples[i].ratio) &&
                 samples[i].r2 >= 0.0f && samples[i].r2 <= 1.0f;
        if (!use[i]) continue;
        ++valid;
        maxR2 = std::max(maxR2, samples[i].r2);
    }
    if (valid < minSamples) {
        why = fmt::format("{} usable blocks, {} needed", valid, minSamples);
        return std::nullopt;
    }
    if (maxR2 < minRadius * minRadius) {
        why = fmt::format("the usable blocks reach r = {:.2f} only, {:.2f} needed",
                          std::sqrt(maxR2), minRadius);
        return std::nullopt;
    }
    glm::dvec3 x(0.0);
    for (int round = 0; round < 3; ++round) {
        if (!solveQuadratic(samples, use, x) || !(x.x > 0.0)) {
            why = "the fit is singular";
            return std::nullopt;
        }
        if (round == 2) break;
        // Relative residuals; drop those beyond 3 robust deviations (at least 2 %).
        std::vector<double> residuals;
        for (size_t i = 0; i < samples.size(); ++i) {
            if (!use[i]) continue;
            const double r2 = samples[i].r2;
            residuals.push_back(
                std::abs(samples[i].ratio / (x.x + x.y * r2 + x.z * r2 * r2) - 1.0));
        }
        const double limit = std::max(0.02, 3.0 * 1.4826 * median(residuals));
        for (size_t i = 0; i < samples.size(); ++i) {
            if (!use[i]) continue;
            const double r2 = samples[i].r2;
            use[i] = std::abs(samples[i].ratio / (x.x + x.y * r2 + x.z * r2 * r2) - 1.0) <= limit;
        }
    }
    VignetteProfile p{float(x.y / x.x), float(x.z / x.x)};
    // A vignetting darkens towards the corners, by at most 80 %: anything else is the model's
    // error, not the lens.
    const float corner = p.gain(1.0f), mid = p.gain(0.25f);
    if (!(corner >= 0.2f && corner <= 1.05f && mid >= 0.2f && mid <= 1.05f)) {
        why = fmt::format("the fit (k1 {:.3f}, k2 {:.3f}) is not a vignetting", p.k1, p.k2);
        return std::nullopt;
    }
    why = fmt::format("fitted to {} blocks", valid);
    return p;
}

void GrainEstimates::updateNoise(const std::optional<NoiseLevelFunction>& frame, float history,
                                 const std::string& why) {
    if (!frame) {
        noiseNote = (noise_ ? "held (" : "none yet (") + why + ")";
        return;
    }
    if (!noise_) {
        noise_ = frame;
    } else {
        const float h = history, w = 1.0f - history;
        for (int l = 0; l < kNoiseLevels; ++l)
            noise_->variance[size_t(l)] =
                h * noise_->variance[size_t(l)] + w * frame->variance[size_t(l)];
        noise_->correlation = h * noise_->correlation + w * frame->correlation;
        noise_->blocks = frame->blocks;
    }
    ++noiseFrames_;
    noiseNote = "measured: " + why;
}

void GrainEstimates::updateVignette(const std::optional<VignetteProfile>& frame, float history,
                                    const std::string& why) {
    if (!frame) {
        vignetteNote = (vignette_ ? "held (" : "none yet (") + why + ")";
        return;
    }
    if (!vignette_) {
        vignette_ = frame;
    } else {
        vignette_->k1 = history * vignette_->k1 + (1.0f - history) * frame->k1;
        vignette_->k2 = history * vignette_->k2 + (1.0f - history) * frame->k2;
    }
    ++vignetteFrames_;
    vignetteNote =
        fmt::format("estimated from the footage over {} frames (k1 {:.3f}, k2 {:.3f}; {})",
                    vignetteFrames_, vignette_->k1, vignette_->k2, why);
}

}  // namespace mirage::render
