#include "render/passes/grain/CameraGrain.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <fmt/format.h>
#include <opencv2/core.hpp>

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

namespace {

struct CellKey {
    int x, y, z;
    bool operator==(const CellKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct CellKeyHash {
    size_t operator()(const CellKey& k) const {
        return size_t(uint64_t(uint32_t(k.x)) * 73856093u ^ uint64_t(uint32_t(k.y)) * 19349663u ^
                      uint64_t(uint32_t(k.z)) * 83492791u);
    }
};

// One sample of the across-frames fit: its frame, cell and values.
struct CellSample {
    int frame, cell;
    double r2, y;  // y = log(footage / L_r)
};

// Least squares of y = c_f + b1 r2 + b2 r2^2 + a_cell over `use`d samples, a_cell eliminated by
// taking every quantity less its cell's mean; c_0 = 0. Returns the residuals' unknowns
// (c_1..c_{F-1}, b1, b2) or nothing when singular; `spread`: the RMS of r2 less its cell's mean.
std::optional<std::vector<double>> solveWithinCells(const std::vector<CellSample>& s,
                                                    const std::vector<bool>& use, int frames,
                                                    int cells, double& spread) {
    const int n = frames - 1 + 2;  // c_1..c_{F-1}, b1, b2
    std::vector<double> count(size_t(cells), 0.0);
    std::vector<std::vector<double>> mean(size_t(cells), std::vector<double>(size_t(n + 1), 0.0));
    auto row = [&](const CellSample& c, std::vector<double>& x) {
        std::fill(x.begin(), x.end(), 0.0);
        if (c.frame > 0) x[size_t(c.frame - 1)] = 1.0;
        x[size_t(n - 2)] = c.r2;
        x[size_t(n - 1)] = c.r2 * c.r2;
        x[size_t(n)] = c.y;
    };
    std::vector<double> x(size_t(n + 1));
    for (size_t i = 0; i < s.size(); ++i) {
        if (!use[i]) continue;
        row(s[i], x);
        count[size_t(s[i].cell)] += 1.0;
        for (int k = 0; k <= n; ++k) mean[size_t(s[i].cell)][size_t(k)] += x[size_t(k)];
    }
    for (int c = 0; c < cells; ++c)
        if (count[size_t(c)] > 0.0)
            for (double& m : mean[size_t(c)]) m /= count[size_t(c)];
    cv::Mat A = cv::Mat::zeros(n, n, CV_64F), b = cv::Mat::zeros(n, 1, CV_64F);
    double spread2 = 0.0, used = 0.0;
    for (size_t i = 0; i < s.size(); ++i) {
        if (!use[i] || count[size_t(s[i].cell)] < 2.0) continue;
        row(s[i], x);
        const std::vector<double>& m = mean[size_t(s[i].cell)];
        for (int k = 0; k <= n; ++k) x[size_t(k)] -= m[size_t(k)];
        for (int r = 0; r < n; ++r) {
            for (int c = 0; c < n; ++c) A.at<double>(r, c) += x[size_t(r)] * x[size_t(c)];
            b.at<double>(r) += x[size_t(r)] * x[size_t(n)];
        }
        spread2 += x[size_t(n - 2)] * x[size_t(n - 2)];
        used += 1.0;
    }
    spread = used > 0.0 ? std::sqrt(spread2 / used) : 0.0;
    cv::Mat theta;
    if (used < double(n) || !cv::solve(A, b, theta, cv::DECOMP_SVD)) return std::nullopt;
    std::vector<double> out(theta.begin<double>(), theta.end<double>());
    for (double v : out)
        if (!std::isfinite(v)) return std::nullopt;
    return out;
}

}  // namespace

std::optional<VignetteProfile> fitVignetteAcrossFrames(
    const std::vector<std::vector<VignetteSample>>& frames, float cellSize, int minSamples,
    float minSpread, std::string& why) {
    std::unordered_map<CellKey, int, CellKeyHash> cellIds;
    std::vector<CellSample> s;
    std::vector<std::vector<int>> cellFrames;  // per cell: the frames that saw it
    const int frameCount = int(frames.size());
    for (int f = 0; f < frameCount; ++f)
        for (const VignetteSample& v : frames[size_t(f)]) {
            if (!(v.ratio > 0.0f) || !std::isfinite(v.ratio) || !(v.r2 >= 0.0f && v.r2 <= 1.0f) ||
                !std::isfinite(v.world.x) || !std::isfinite(v.world.y) || !std::isfinite(v.world.z))
                continue;
            const glm::vec3 q = glm::floor(v.world / cellSize);
            const CellKey key{int(q.x), int(q.y), int(q.z)};
            const auto [it, added] = cellIds.try_emplace(key, int(cellFrames.size()));
            if (added) cellFrames.emplace_back();
            std::vector<int>& seen = cellFrames[size_t(it->second)];
            if (seen.empty() || seen.back() != f) seen.push_back(f);
            s.push_back({f, it->second, double(v.r2), std::log(double(v.ratio))});
        }
    std::vector<bool> use(s.size());
    int multi = 0;
    for (size_t i = 0; i < s.size(); ++i) {
        use[i] = cellFrames[size_t(s[i].cell)].size() >= 2;
        multi += use[i] ? 1 : 0;
    }
    if (frameCount < 2 || multi < minSamples) {
        why = fmt::format("{} samples of surface points seen in two frames or more, {} needed",
                          multi, minSamples);
        return std::nullopt;
    }
    std::optional<std::vector<double>> theta;
    double spread = 0.0;
    for (int round = 0; round < 3; ++round) {
        theta = solveWithinCells(s, use, frameCount, int(cellFrames.size()), spread);
        if (!theta) {
            why = "the fit is singular";
            return std::nullopt;
        }
        if (round == 0 && spread < minSpread) {
            why = fmt::format(
                "the camera moved too little: the same surfaces at image radii (r^2) {:.3f} "
                "apart, {:.3f} needed",
                spread, minSpread);
            return std::nullopt;
        }
        if (round == 2) break;
        // Residuals about each cell's mean residual (the cell's a_p), then 3 robust deviations.
        const double b1 = (*theta)[size_t(frameCount - 1)], b2 = (*theta)[size_t(frameCount)];
        auto model = [&](const CellSample& c) {
            return (c.frame > 0 ? (*theta)[size_t(c.frame - 1)] : 0.0) + b1 * c.r2 +
                   b2 * c.r2 * c.r2;
        };
        std::vector<double> cellSum(cellFrames.size(), 0.0), cellCount(cellFrames.size(), 0.0);
        for (size_t i = 0; i < s.size(); ++i)
            if (use[i]) {
                cellSum[size_t(s[i].cell)] += s[i].y - model(s[i]);
                cellCount[size_t(s[i].cell)] += 1.0;
            }
        std::vector<double> residual(s.size(), 0.0), absResiduals;
        for (size_t i = 0; i < s.size(); ++i)
            if (use[i]) {
                const size_t c = size_t(s[i].cell);
                residual[i] = s[i].y - model(s[i]) - cellSum[c] / cellCount[c];
                absResiduals.push_back(std::abs(residual[i]));
            }
        const double limit = std::max(0.02, 3.0 * 1.4826 * median(absResiduals));
        for (size_t i = 0; i < s.size(); ++i)
            if (use[i]) use[i] = std::abs(residual[i]) <= limit;
    }
    const double b1 = (*theta)[size_t(frameCount - 1)], b2 = (*theta)[size_t(frameCount)];
    VignetteProfile p{float(b1), float(b2 + 0.5 * b1 * b1)};
    const float corner = p.gain(1.0f), mid = p.gain(0.25f);
    if (!(corner >= 0.2f && corner <= 1.05f && mid >= 0.2f && mid <= 1.05f)) {
        why = fmt::format("the fit (k1 {:.3f}, k2 {:.3f}) is not a vignetting", p.k1, p.k2);
        return std::nullopt;
    }
    why =
        fmt::format("fitted to {} samples of surface points seen in {} frames (r^2 spread {:.3f})",
                    multi, frameCount, spread);
    return p;
}

void GrainEstimates::addVignetteSamples(std::vector<VignetteSample> frame, size_t keep) {
    vignetteSamples_.push_back(std::move(frame));
    while (vignetteSamples_.size() > std::max<size_t>(keep, 1))
        vignetteSamples_.erase(vignetteSamples_.begin());
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
