#include "tracking/SyntheticBoardView.h"

#include <cmath>

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

    cv::Mat mapX(H, W, CV_32F), mapY(H, W, CV_32F);
    cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& rows) {
        for (int yh = rows.start; yh < rows.end; ++yh) {
            float* mx = mapX.ptr<float>(yh);
            float* my = mapY.ptr<float>(yh);
            for (int xh = 0; xh < W; ++xh) {
                // Supersample centre in output pixel coordinates (block of s x s per pixel).
                // Stratified: a deterministic hash jitters each sample inside its sub-cell, so
                // edges aligned with the pixel grid are not quantised to 1/s steps.
                uint32_t h = uint32_t(xh) * 73856093u ^ uint32_t(yh) * 19349663u;
                h ^= h >> 13;
                h *= 0x5bd1e995u;
                h ^= h >> 15;
                const double jx = (h & 0xffffu) / 65536.0 - 0.5, jy = (h >> 16) / 65536.0 - 0.5;
                const double jitter = s > 1 ? 1.0 : 0.0;
                const glm::dvec2 px{(xh + jitter * jx - 0.5 * (s - 1)) / s,
                                    (yh + jitter * jy - 0.5 * (s - 1)) / s};
                glm::dvec3 ray;
                if (noDistortion) {
                    ray = {(px.x - camera.cx) / camera.fx, (px.y - camera.cy) / camera.fy, 1.0};
                } else {
                    auto r = camera.unproject(px);
                    if (!r) {
                        mx[xh] = my[xh] = -1e6f;
                        continue;
                    }
                    ray = *r;
                }
                const glm::dvec3 d = R * ray;
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
    cv::Mat texLinear(texture.image.size(), CV_32F);
    for (int i = 0; i < texture.image.rows; ++i)
        for (int j = 0; j < texture.image.cols; ++j)
            texLinear.at<float>(i, j) = lut.at<float>(texture.image.at<uint8_t>(i, j));
    cv::Mat sampled;
    cv::remap(texLinear, sampled, mapX, mapY, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
              cv::Scalar(-1.0));
    const float paper = srgbToLinear(options.paper / 255.0f),
                ink = srgbToLinear(options.ink / 255.0f);
    const float bg = srgbToLinear(options.background / 255.0f);
    cv::Mat linear(H, W, CV_32F);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const float c = sampled.at<float>(y, x);
            linear.at<float>(y, x) = c < 0 ? bg : ink + (paper - ink) * std::min(c, 1.0f);
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
