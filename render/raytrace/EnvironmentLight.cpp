#include "render/raytrace/EnvironmentLight.h"

#include <cmath>

#include "core/Error.h"

namespace mirage::raytrace {

EnvironmentLight::EnvironmentLight(const cv::Mat& linearRgb, float scale, double rotationYDeg) {
    if (linearRgb.empty() || linearRgb.channels() != 3)
        throw Error("environment light: the image must be a non-empty 3-channel linear RGB image");
    if (!(scale >= 0.0f) || !std::isfinite(scale))
        throw Error("environment light: intensity must be finite and >= 0 (got " +
                    std::to_string(scale) + ")");
    linearRgb.convertTo(image_, CV_32FC3, scale);
    double rot = rotationYDeg * 3.14159265358979323846 / 180.0;
    cosRot_ = float(std::cos(rot));
    sinRot_ = float(std::sin(rot));
    int w = image_.cols, h = image_.rows;
    std::vector<float> weights(size_t(w) * h);
    double sum = 0.0, solid = 0.0;
    for (int y = 0; y < h; ++y) {
        float sinT = std::sin(kPi * (float(y) + 0.5f) / float(h));
        for (int x = 0; x < w; ++x) {
            const auto& c = image_.at<cv::Vec3f>(y, x);
            for (int k = 0; k < 3; ++k)
                if (!std::isfinite(c[k]) || c[k] < 0)
                    throw Error("environment light: pixel (" + std::to_string(x) + ", " +
                                std::to_string(y) + ") is negative or not finite; fix the image");
            float m = std::max(c[0], std::max(c[1], c[2]));
            weights[size_t(y) * w + x] = m * sinT;
            sum += double(0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]) * sinT;
            solid += sinT;
        }
    }
    averageRadiance_ = solid > 0 ? float(sum / solid) : 0.0f;
    distribution_ = Distribution2D(weights, w, h);
}

glm::vec2 EnvironmentLight::directionToUv(const glm::vec3& d) const {
    // Undo the map's rotation about +Y (rotate the direction by -rot).
    glm::vec3 l{cosRot_ * d.x - sinRot_ * d.z, d.y, sinRot_ * d.x + cosRot_ * d.z};
    float u = 0.5f + std::atan2(l.x, -l.z) / (2.0f * kPi);
    float v = std::acos(std::clamp(l.y, -1.0f, 1.0f)) / kPi;
    return {u - std::floor(u), v};
}

glm::vec3 EnvironmentLight::uvToDirection(glm::vec2 uv) const {
    float theta = uv.y * kPi, phi = (uv.x - 0.5f) * 2.0f * kPi;
    glm::vec3 l{std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi)};
    return {cosRot_ * l.x + sinRot_ * l.z, l.y, -sinRot_ * l.x + cosRot_ * l.z};
}

glm::vec3 EnvironmentLight::texel(glm::vec2 uv) const {
    int x = std::clamp(int(uv.x * float(image_.cols)), 0, image_.cols - 1);
    int y = std::clamp(int(uv.y * float(image_.rows)), 0, image_.rows - 1);
    const auto& c = image_.at<cv::Vec3f>(y, x);
    return {c[0], c[1], c[2]};
}

glm::vec3 EnvironmentLight::radiance(const glm::vec3& dirWorld) const {
    return texel(directionToUv(dirWorld));
}

glm::vec3 EnvironmentLight::sample(glm::vec2 u, glm::vec3& dirWorld, float& pdf) const {
    float pdfUv;
    glm::vec2 uv = distribution_.sample(u, pdfUv);
    float sinT = std::sin(uv.y * kPi);
    if (!(pdfUv > 0) || sinT <= 0) {
        pdf = 0;
        return glm::vec3(0.0f);
    }
    dirWorld = uvToDirection(uv);
    pdf = pdfUv / (2.0f * kPi * kPi * sinT);
    return texel(uv);
}

float EnvironmentLight::pdf(const glm::vec3& dirWorld) const {
    glm::vec2 uv = directionToUv(dirWorld);
    float sinT = std::sin(uv.y * kPi);
    if (sinT <= 0) return 0.0f;
    return distribution_.pdf(uv) / (2.0f * kPi * kPi * sinT);
}

}  // namespace mirage::raytrace
