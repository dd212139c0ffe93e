#pragma once
// Random numbers and sample warps for the reference renderer. Everything here is deterministic:
// a Rng is seeded from (seed, stream) — e.g. (render seed, pixel index + pass) — so images do not
// depend on how work is split across threads.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace mirage::raytrace {

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 0.31830988618379067154f;

// 64-bit finaliser of SplitMix64: decorrelates consecutive seeds.
inline uint64_t mixBits(uint64_t v) {
    v ^= v >> 31;
    v *= 0x7fb5d329728ea185ull;
    v ^= v >> 27;
    v *= 0x81dadef4bc2dd44dull;
    v ^= v >> 33;
    return v;
}

// PCG32 (O'Neill 2014): small state, good statistics, cheap to seed per pixel.
class Rng {
public:
    Rng(uint64_t seed, uint64_t stream) {
        inc_ = (mixBits(stream) << 1u) | 1u;
        state_ = 0;
        next();
        state_ += mixBits(seed);
        next();
    }
    uint32_t next() {
        uint64_t old = state_;
        state_ = old * 6364136223846793005ull + inc_;
        auto xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
        auto rot = static_cast<uint32_t>(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31u));
    }
    // Uniform in [0, 1).
    float uniform() { return std::min(float(next()) * 0x1p-32f, 0x1.fffffep-1f); }
    glm::vec2 uniform2() {
        float a = uniform();
        return {a, uniform()};
    }

private:
    uint64_t state_ = 0, inc_ = 0;
};

inline float luminance(const glm::vec3& c) {
    return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b;
}
inline float maxComponent(const glm::vec3& c) {
    return std::max(c.r, std::max(c.g, c.b));
}
inline bool isFiniteVec(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Orthonormal basis around a unit normal (Duff et al. 2017, branchless).
struct Frame {
    glm::vec3 t, b, n;
    explicit Frame(const glm::vec3& normal) : n(normal) {
        float sign = std::copysign(1.0f, n.z);
        float a = -1.0f / (sign + n.z);
        float bb = n.x * n.y * a;
        t = {1.0f + sign * n.x * n.x * a, sign * bb, -sign * n.x};
        b = {bb, sign + n.y * n.y * a, -n.y};
    }
    glm::vec3 toLocal(const glm::vec3& v) const {
        return {glm::dot(v, t), glm::dot(v, b), glm::dot(v, n)};
    }
    glm::vec3 toWorld(const glm::vec3& v) const { return v.x * t + v.y * b + v.z * n; }
};

inline glm::vec3 sampleCosineHemisphere(glm::vec2 u) {
    float r = std::sqrt(u.x), phi = 2.0f * kPi * u.y;
    return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u.x))};
}
inline glm::vec3 sampleUniformSphere(glm::vec2 u) {
    float z = 1.0f - 2.0f * u.x, r = std::sqrt(std::max(0.0f, 1.0f - z * z)),
          phi = 2.0f * kPi * u.y;
    return {r * std::cos(phi), r * std::sin(phi), z};
}
// Uniform direction in the cone of half-angle acos(cosMax) around +Z; pdf = 1/(2 pi (1-cosMax)).
inline glm::vec3 sampleUniformCone(glm::vec2 u, float cosMax) {
    float cosT = 1.0f - u.x * (1.0f - cosMax), sinT = std::sqrt(std::max(0.0f, 1.0f - cosT * cosT));
    float phi = 2.0f * kPi * u.y;
    return {sinT * std::cos(phi), sinT * std::sin(phi), cosT};
}
inline glm::vec2 sampleUniformDisk(glm::vec2 u) {
    float r = std::sqrt(u.x), phi = 2.0f * kPi * u.y;
    return {r * std::cos(phi), r * std::sin(phi)};
}
inline float powerHeuristic(float a, float b) {
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

// Piecewise-constant 1D distribution over [0,1) with n cells.
class Distribution1D {
public:
    Distribution1D() = default;
    explicit Distribution1D(std::vector<float> f) : func_(std::move(f)), cdf_(func_.size() + 1) {
        cdf_[0] = 0.0;
        size_t n = func_.size();
        for (size_t i = 0; i < n; ++i)
            cdf_[i + 1] = cdf_[i] + double(std::max(func_[i], 0.0f)) / double(n);
        integral_ = cdf_[n];
        for (size_t i = 1; i <= n; ++i)
            cdf_[i] = integral_ > 0 ? cdf_[i] / integral_ : double(i) / double(n);
    }
    size_t size() const { return func_.size(); }
    double integral() const { return integral_; }
    // Returns a continuous sample in [0,1), its pdf (w.r.t. [0,1)) and the cell index.
    float sample(float u, float& pdf, size_t& cell) const {
        auto it = std::upper_bound(cdf_.begin(), cdf_.end(), double(u));
        cell = std::clamp<size_t>(size_t(it - cdf_.begin()) - 1, 0, func_.size() - 1);
        double width = cdf_[cell + 1] - cdf_[cell];
        double du = width > 0 ? (u - cdf_[cell]) / width : 0.5;
        pdf = integral_ > 0 ? float(std::max(func_[cell], 0.0f) / integral_) : 1.0f;
        return std::min(float((double(cell) + std::clamp(du, 0.0, 1.0)) / double(func_.size())),
                        0x1.fffffep-1f);
    }
    float pdf(size_t cell) const {
        return integral_ > 0 ? float(std::max(func_[cell], 0.0f) / integral_) : 1.0f;
    }

private:
    std::vector<float> func_;
    std::vector<double> cdf_;
    double integral_ = 0.0;
};

// Piecewise-constant 2D distribution over [0,1)^2 (rows = v, columns = u).
class Distribution2D {
public:
    Distribution2D() = default;
    Distribution2D(const std::vector<float>& f, int nu, int nv) {
        std::vector<float> marginal(nv);
        for (int v = 0; v < nv; ++v) {
            conditional_.emplace_back(
                std::vector<float>(f.begin() + v * nu, f.begin() + (v + 1) * nu));
            marginal[v] = float(conditional_.back().integral());
        }
        marginal_ = Distribution1D(std::move(marginal));
    }
    bool empty() const { return conditional_.empty(); }
    glm::vec2 sample(glm::vec2 u, float& pdf) const {
        float pv, pu;
        size_t v, ucell;
        float sv = marginal_.sample(u.y, pv, v);
        float su = conditional_[v].sample(u.x, pu, ucell);
        pdf = pv * pu;
        return {su, sv};
    }
    float pdf(glm::vec2 uv) const {
        auto nv = conditional_.size(), nu = conditional_[0].size();
        size_t v = std::min(size_t(std::max(0.0f, uv.y) * float(nv)), nv - 1);
        size_t u = std::min(size_t(std::max(0.0f, uv.x) * float(nu)), nu - 1);
        return marginal_.pdf(v) * conditional_[v].pdf(u);
    }

private:
    std::vector<Distribution1D> conditional_;
    Distribution1D marginal_;
};

}  // namespace mirage::raytrace
