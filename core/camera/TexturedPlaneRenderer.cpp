#include "core/camera/TexturedPlaneRenderer.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/Error.h"
#include "core/image/ImageIO.h"

namespace mirage {
namespace {

// Coarse ray grid spacing, in sub-pixels.
constexpr int kStep = 4;

const std::array<float, 256>& srgbLut() {
    static const std::array<float, 256> lut = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[size_t(i)] = srgbToLinear(float(i) / 255.0f);
        return t;
    }();
    return lut;
}

float linearOfLevel(double srgbLevel) {
    return srgbToLinear(float(std::clamp(srgbLevel, 0.0, 255.0) / 255.0));
}

}  // namespace

TexturedPlaneRenderer::TexturedPlaneRenderer(const CameraIntrinsics& camera, int supersample)
    : camera_(camera), n_(supersample) {
    if (!camera.isValid()) throw Error("plane renderer: invalid camera intrinsics");
    if (supersample < 1)
        throw Error("plane renderer: supersample must be at least 1 (sub-pixels per axis)");
    noDistortion_ = camera.model == DistortionModel::BrownConrady;
    for (double d : camera.distortion) noDistortion_ = noDistortion_ && d == 0.0;
    const int W = camera.width * n_, H = camera.height * n_;
    gridW_ = W / kStep + 2;
    gridH_ = H / kStep + 2;
    grid_.resize(size_t(gridW_) * size_t(gridH_));
    gridOk_.resize(grid_.size());
    cv::parallel_for_(cv::Range(0, gridH_), [&](const cv::Range& rows) {
        for (int gy = rows.start; gy < rows.end; ++gy)
            for (int gx = 0; gx < gridW_; ++gx) {
                const size_t i = size_t(gy) * size_t(gridW_) + size_t(gx);
                const auto r =
                    exactRay({(gx * kStep + 0.5) / n_ - 0.5, (gy * kStep + 0.5) / n_ - 0.5});
                gridOk_[i] = r.has_value();
                if (r) grid_[i] = *r;
            }
    });
}

std::optional<glm::dvec3> TexturedPlaneRenderer::exactRay(const glm::dvec2& px) const {
    if (noDistortion_)
        return glm::dvec3((px.x - camera_.cx) / camera_.fx, (px.y - camera_.cy) / camera_.fy, 1.0);
    const auto r = camera_.unproject(px);
    if (!r) return std::nullopt;
    // Pinhole rays on the z = 1 plane, fish-eye rays as unit vectors (which stay smooth up to and
    // beyond 90 degrees off-axis); the plane intersection needs no normalisation.
    if (camera_.model == DistortionModel::BrownConrady) return *r / r->z;
    return *r;
}

std::optional<glm::dvec3> TexturedPlaneRenderer::subPixelRay(double xh, double yh) const {
    // Sub-pixel coordinate h has its centre at pixel (h + 0.5) / n - 0.5.
    const double gxf = xh / kStep, gyf = yh / kStep;
    const int gx = std::clamp(int(std::floor(gxf)), 0, gridW_ - 2);
    const int gy = std::clamp(int(std::floor(gyf)), 0, gridH_ - 2);
    const size_t i00 = size_t(gy) * size_t(gridW_) + size_t(gx);
    const size_t i10 = i00 + 1, i01 = i00 + size_t(gridW_), i11 = i01 + 1;
    if (gridOk_[i00] && gridOk_[i10] && gridOk_[i01] && gridOk_[i11]) {
        const double fx = gxf - gx, fy = gyf - gy;
        return (1 - fy) * ((1 - fx) * grid_[i00] + fx * grid_[i10]) +
               fy * ((1 - fx) * grid_[i01] + fx * grid_[i11]);
    }
    if (!gridOk_[i00] && !gridOk_[i10] && !gridOk_[i01] && !gridOk_[i11]) {
        // Wholly outside the field of view (beyond a fish-eye's image circle) unless the cell
        // straddles its edge, which a node would show.
        return std::nullopt;
    }
    return exactRay({(xh + 0.5) / n_ - 0.5, (yh + 0.5) / n_ - 0.5});
}

std::optional<glm::dvec3> TexturedPlaneRenderer::rayAt(const glm::dvec2& pixel) const {
    return subPixelRay((pixel.x + 0.5) * n_ - 0.5, (pixel.y + 0.5) * n_ - 0.5);
}

cv::Mat TexturedPlaneRenderer::render(const PlaneTexture& tex, const Pose& T_camera_plane,
                                      const PlaneShading& shading) const {
    if (tex.image.empty() || tex.image.type() != CV_8UC1)
        throw Error("plane renderer: the texture must be a non-empty 8-bit grey image");
    if (!(tex.metresPerTexelX > 0) || !(tex.metresPerTexelY > 0))
        throw Error("plane renderer: texel sizes must be positive (metres per texel)");
    const auto& lut = srgbLut();
    const Pose T_plane_camera = T_camera_plane.inverse();
    const glm::dmat3 R = T_plane_camera.rotationMatrix();
    const glm::dvec3 o = T_plane_camera.translation;  // camera centre in the plane frame
    const float black = linearOfLevel(shading.black), white = linearOfLevel(shading.white);
    const float background = linearOfLevel(shading.background);
    const int tw = tex.image.cols, th = tex.image.rows;
    const bool bilinear = tex.filter == PlaneTexture::Filter::Bilinear;
    const double jitter = n_ > 1 ? 1.0 : 0.0;

    // Linear reflectance of the texture at plane point (x, y) in [0, 1], or -1 off the texture.
    auto sample = [&](double x, double y) -> float {
        const double u = (x - tex.originMetres.x) / tex.metresPerTexelX;
        const double v = (y - tex.originMetres.y) / tex.metresPerTexelY;
        if (!(u >= 0 && v >= 0 && u < tw && v < th)) return -1.0f;
        if (!bilinear) return lut[tex.image.at<uint8_t>(int(v), int(u))];
        // Texel centres at half-integers; clamp at the border (the texture ends there).
        const double us = u - 0.5, vs = v - 0.5;
        const int u0 = int(std::floor(us)), v0 = int(std::floor(vs));
        const float fu = float(us - u0), fv = float(vs - v0);
        const int ua = std::clamp(u0, 0, tw - 1), ub = std::clamp(u0 + 1, 0, tw - 1);
        const int va = std::clamp(v0, 0, th - 1), vb = std::clamp(v0 + 1, 0, th - 1);
        const uint8_t* ra = tex.image.ptr<uint8_t>(va);
        const uint8_t* rb = tex.image.ptr<uint8_t>(vb);
        return (1 - fv) * ((1 - fu) * lut[ra[ua]] + fu * lut[ra[ub]]) +
               fv * ((1 - fu) * lut[rb[ua]] + fu * lut[rb[ub]]);
    };

    cv::Mat out(camera_.height, camera_.width, CV_8UC1);
    cv::parallel_for_(cv::Range(0, camera_.height), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
            auto* dst = out.ptr<uint8_t>(y);
            for (int x = 0; x < camera_.width; ++x) {
                float sum = 0;
                for (int sy = 0; sy < n_; ++sy)
                    for (int sx = 0; sx < n_; ++sx) {
                        const int xh = x * n_ + sx, yh = y * n_ + sy;
                        // Stratified: a deterministic hash jitters each sample in its sub-cell.
                        uint32_t h = uint32_t(xh) * 73856093u ^ uint32_t(yh) * 19349663u;
                        h ^= h >> 13;
                        h *= 0x5bd1e995u;
                        h ^= h >> 15;
                        const double jx = xh + jitter * ((h & 0xffffu) / 65536.0 - 0.5);
                        const double jy = yh + jitter * ((h >> 16) / 65536.0 - 0.5);
                        float value = background;
                        if (const auto ray = subPixelRay(jx, jy)) {
                            const glm::dvec3 d = R * *ray;
                            const double t = -o.z / d.z;
                            if (std::abs(d.z) > 1e-12 && t > 0) {
                                const float s = sample(o.x + t * d.x, o.y + t * d.y);
                                if (s >= 0) value = black + (white - black) * std::min(s, 1.0f);
                            }
                        }
                        sum += value;
                    }
                const float mean = std::clamp(sum / float(n_ * n_), 0.0f, 1.0f);
                dst[x] = uint8_t(std::lround(255.0f * linearToSrgb(mean)));
            }
        }
    });
    return out;
}

}  // namespace mirage
