#include "render/LightEstimation.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/Error.h"
#include "core/camera/EquirectProjection.h"

namespace mirage::render {
namespace {

float luminance(const glm::vec3& c) {
    return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b;
}

}  // namespace

glm::vec3 EstimatedLight::color() const {
    const float m = std::max({irradiance.r, irradiance.g, irradiance.b});
    return m > 0 ? irradiance / m : glm::vec3(1.0f);
}

float EstimatedLight::intensity() const {
    return std::max({irradiance.r, irradiance.g, irradiance.b});
}

std::vector<EstimatedLight> estimateLights(const cv::Mat& map, const LightEstimationOptions& o,
                                           cv::Mat* regions) {
    if (map.empty() || (map.type() != CV_32FC3 && map.type() != CV_32FC4))
        throw Error("light estimation: the map must be linear RGB(A) float");
    const int W = map.cols, H = map.rows;
    const bool hasAlpha = map.channels() == 4;
    std::vector<glm::vec3> rgb(size_t(W) * H);
    std::vector<float> lum(rgb.size()), omega(rgb.size());
    std::vector<uint8_t> seen(rgb.size());
    std::vector<float> seenLum;
    double budget = 0;  // luminance irradiance of the whole seen map (sum L dOmega)
    for (int y = 0; y < H; ++y) {
        const float lat = float(M_PI / 2 - M_PI * (y + 0.5) / H);
        const float dOmega = std::cos(lat) * float(M_PI / H) * float(2 * M_PI / W);
        for (int x = 0; x < W; ++x) {
            const size_t i = size_t(y) * W + x;
            const float* p = map.ptr<float>(y) + x * map.channels();
            rgb[i] = glm::vec3(p[0], p[1], p[2]);
            for (int c = 0; c < 3; ++c)
                if (!std::isfinite(rgb[i][c]) || rgb[i][c] < 0) rgb[i][c] = 0;
            lum[i] = luminance(rgb[i]);
            omega[i] = dOmega;
            seen[i] = !hasAlpha || p[3] >= 0.5f;
            if (seen[i]) {
                seenLum.push_back(lum[i]);
                budget += double(lum[i]) * dOmega;
            }
        }
    }
    if (regions) *regions = cv::Mat(H, W, CV_32S, cv::Scalar(-1));
    if (seenLum.empty() || budget <= 0) return {};
    // Background: the median of the seen texels (per channel for the excess).
    auto median = [](std::vector<float> v) {
        std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
        return v[v.size() / 2];
    };
    const float medLum = median(seenLum);
    glm::vec3 background(0.0f);
    for (int c = 0; c < 3; ++c) {
        std::vector<float> ch;
        ch.reserve(seenLum.size());
        for (size_t i = 0; i < rgb.size(); ++i)
            if (seen[i]) ch.push_back(rgb[i][c]);
        background[c] = median(std::move(ch));
    }
    const float threshold = std::max(o.brightFactor * medLum, 1e-6f);

    // Connected regions of bright seen texels (8-neighbours, wrapping in x).
    std::vector<int> label(rgb.size(), -1);
    std::vector<EstimatedLight> lights;
    std::vector<size_t> stack;
    for (size_t start = 0; start < rgb.size(); ++start) {
        if (label[start] >= 0 || !seen[start] || lum[start] <= threshold) continue;
        const int id = int(lights.size());
        label[start] = id;
        stack.assign(1, start);
        glm::dvec3 dirSum(0.0), irr(0.0);
        double solid = 0, excessSum = 0;
        while (!stack.empty()) {
            const size_t i = stack.back();
            stack.pop_back();
            const int x = int(i % size_t(W)), y = int(i / size_t(W));
            const glm::dvec3 d = equirectDirection(x + 0.5, y + 0.5, W, H);
            const double excess = std::max(0.0, double(lum[i] - medLum)) * omega[i];
            dirSum += d * excess;
            excessSum += excess;
            irr += glm::dvec3(glm::max(rgb[i] - background, glm::vec3(0.0f))) * double(omega[i]);
            solid += omega[i];
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int ny = y + dy;
                    if (ny < 0 || ny >= H || (dx == 0 && dy == 0)) continue;
                    const int nx = (x + dx + W) % W;
                    const size_t j = size_t(ny) * W + nx;
                    if (label[j] >= 0 || !seen[j] || lum[j] <= threshold) continue;
                    label[j] = id;
                    stack.push_back(j);
                }
        }
        EstimatedLight l;
        l.direction =
            glm::length(dirSum) > 0 ? glm::vec3(glm::normalize(dirSum)) : glm::vec3(0, 1, 0);
        l.irradiance = glm::vec3(irr);
        l.solidAngleSr = float(solid);
        l.share = float(excessSum / budget);
        lights.push_back(l);
    }
    std::vector<int> kept;  // region ids, strongest first
    for (size_t i = 0; i < lights.size(); ++i)
        if (lights[i].solidAngleSr <= o.maxSolidAngleSr && lights[i].share >= o.minShare)
            kept.push_back(int(i));
    std::stable_sort(kept.begin(), kept.end(), [&](int a, int b) {
        return lights[size_t(a)].share > lights[size_t(b)].share;
    });
    if (int(kept.size()) > o.maxLights) kept.resize(size_t(std::max(o.maxLights, 0)));
    std::vector<EstimatedLight> out;
    std::vector<int> outIndex(lights.size(), -1);
    for (int id : kept) {
        outIndex[size_t(id)] = int(out.size());
        out.push_back(lights[size_t(id)]);
    }
    if (regions)
        for (size_t i = 0; i < label.size(); ++i)
            if (label[i] >= 0)
                regions->at<int>(int(i / size_t(W)), int(i % size_t(W))) =
                    outIndex[size_t(label[i])];
    return out;
}

}  // namespace mirage::render
