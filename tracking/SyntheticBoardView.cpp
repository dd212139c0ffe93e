#include "tracking/SyntheticBoardView.h"

#include <cmath>
#include <optional>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/image/ImageIO.h"

namespace mirage::tracking {

cv::Mat renderSyntheticBoardView(const Board& board, const BoardRaster& texture,
                                 const CameraIntrinsics& camera, const Pose& T_world_camera,
                                 const SyntheticViewOptions& options) {
    if (!board.sheet) throw Error("synthetic view: the board has no sheet to render");
    if (!camera.isValid()) throw Error("synthetic view: invalid camera intrinsics");
    const int s = std::max(1, options.supersample);
    const int W = camera.width * s, H = camera.height * s;
    const BoardSheet& sh = *board.sheet;
    const Pose T_sheet_camera = sh.T_world_sheet.inverse() * T_world_camera;
    const glm::dmat3 R = T_sheet_camera.rotationMatrix();
    const glm::dvec3 o = T_sheet_camera.translation;
    bool noDistortion = camera.model == DistortionModel::BrownConrady;
    for (double d : camera.distortion) noDistortion = noDistortion && d == 0.0;

    // Camera rays on a coarse grid (every kStep supersamples), interpolated bilinearly in between:
    // the lens mapping is smooth, so this is exact to ~1e-3 px and saves most unprojections.
    // Cells touching an invalid ray (outside the fish-eye's field) are unprojected per sample.
    constexpr int kStep = 8;
    const int gw = W / kStep + 2, gh = H / kStep + 2;
    auto rayAt = [&](double xh, double yh) -> std::optional<glm::dvec3> {
        const glm::dvec2 px{(xh - 0.5 * (s - 1)) / s, (yh - 0.5 * (s - 1)) / s};
        if (noDistortion)
            return glm::dvec3((px.x - camera.cx) / camera.fx, (px.y - camera.cy) / camera.fy, 1.0);
        auto r = camera.unproject(px);
        if (!r) return std::nullopt;
        // Pinhole rays on the z = 1 plane, fish-eye rays as unit vectors (which stay smooth up to
        // and beyond 90 degrees off-axis); the plane intersection below needs no normalisation.
        if (camera.model == DistortionModel::BrownConrady) return *r / r->z;
        return *r;
    };
    std::vector<glm::dvec3> grid(size_t(gw * gh));
    std::vector<uint8_t> gridOk(size_t(gw * gh));
    cv::parallel_for_(cv::Range(0, gh), [&](const cv::Range& rows) {
        for (int gy = rows.start; gy < rows.end; ++gy)
            for (int gx = 0; gx < gw; ++gx) {
                auto r = rayAt(gx * kStep, gy * kStep);
                gridOk[size_t(gy * gw + gx)] = r.has_value();
                if (r) grid[size_t(gy * gw + gx)] = *r;
            }
    });

    cv::Mat mapX(H, W, CV_32F), mapY(H, W, CV_32F);
    cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& rows) {
        for (int yh = rows.start; yh < rows.end; ++yh) {
            float* mx = mapX.ptr<float>(yh);
            float* my = mapY.ptr<float>(yh);
            for (int xh = 0; xh < W; ++xh) {
                // Stratified: a deterministic hash jitters each sample inside its sub-cell, so
                // edges aligned with the pixel grid are not quantised to 1/s steps.
                uint32_t h = uint32_t(xh) * 73856093u ^ uint32_t(yh) * 19349663u;
                h ^= h >> 13;
                h *= 0x5bd1e995u;
                h ^= h >> 15;
                const double jitter = s > 1 ? 1.0 : 0.0;
                const double sx = xh + jitter * ((h & 0xffffu) / 65536.0 - 0.5);
                const double sy = yh + jitter * ((h >> 16) / 65536.0 - 0.5);
                const int gx = std::clamp(int(std::floor(sx / kStep)), 0, gw - 2);
                const int gy = std::clamp(int(std::floor(sy / kStep)), 0, gh - 2);
                const size_t i00 = size_t(gy * gw + gx);
                std::optional<glm::dvec3> ray;
                if (gridOk[i00] && gridOk[i00 + 1] && gridOk[i00 + size_t(gw)] &&
                    gridOk[i00 + size_t(gw) + 1]) {
                    const double fx = sx / kStep - gx, fy = sy / kStep - gy;
                    ray =
                        (1 - fy) * ((1 - fx) * grid[i00] + fx * grid[i00 + 1]) +
                        fy * ((1 - fx) * grid[i00 + size_t(gw)] + fx * grid[i00 + size_t(gw) + 1]);
                } else {
                    ray = rayAt(sx, sy);
                }
                if (!ray) {
                    mx[xh] = my[xh] = -1e6f;
                    continue;
                }
                const glm::dvec3 d = R * *ray;
                const double t = -o.z / d.z;
                if (!(std::abs(d.z) > 1e-12) || !(t > 0)) {
                    mx[xh] = my[xh] = -1e6f;
                    continue;
                }
                const glm::dvec3 p = o + t * d;
                // Page metres -> texture pixel coordinates (texel j's centre at (j+0.5)*mpp).
                mx[xh] = float((p.x + 0.5 * sh.width) / texture.metresPerPixelX - 0.5);
                my[xh] = float((p.y + 0.5 * sh.height) / texture.metresPerPixelY - 0.5);
            }
        }
    });
    // Texture (sRGB-encoded coverage) -> linear coverage, sampled; -1 marks "missed the sheet".
    cv::Mat lut(1, 256, CV_32F);
    for (int i = 0; i < 256; ++i) lut.at<float>(i) = srgbToLinear(i / 255.0f);
    cv::Mat texLinear;
    cv::LUT(texture.image, lut, texLinear);
    cv::Mat sampled;
    cv::remap(texLinear, sampled, mapX, mapY, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
              cv::Scalar(-1.0));
    const float paper = srgbToLinear(options.paper / 255.0f),
                ink = srgbToLinear(options.ink / 255.0f);
    const float bg = srgbToLinear(options.background / 255.0f);
    cv::Mat linear(H, W, CV_32F);
    for (int y = 0; y < H; ++y) {
        const float* src = sampled.ptr<float>(y);
        float* dst = linear.ptr<float>(y);
        for (int x = 0; x < W; ++x)
            dst[x] = src[x] < 0 ? bg : ink + (paper - ink) * std::min(src[x], 1.0f);
    }
    cv::Mat small;
    if (s > 1)
        cv::resize(linear, small, cv::Size(camera.width, camera.height), 0, 0, cv::INTER_AREA);
    else
        small = linear;
    cv::Mat out(camera.height, camera.width, CV_8UC1);
    for (int y = 0; y < out.rows; ++y)
        for (int x = 0; x < out.cols; ++x)
            out.at<uint8_t>(y, x) = uint8_t(
                std::lround(255.0f * linearToSrgb(std::clamp(small.at<float>(y, x), 0.0f, 1.0f))));
    return out;
}

}  // namespace mirage::tracking
