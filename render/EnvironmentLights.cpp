#include "render/EnvironmentLights.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/image/ImageIO.h"
#include "render/GpuScene.h"

namespace mirage::render {
namespace {

// Dilation of a CV_8U mask of an equirectangular map by `texels`, wrapping around in longitude.
cv::Mat dilateWrapped(const cv::Mat& mask, int texels) {
    cv::Mat padded, grown;
    cv::copyMakeBorder(mask, padded, 0, 0, texels, texels, cv::BORDER_WRAP);
    cv::dilate(padded, grown,
               cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * texels + 1, 2 * texels + 1)));
    return grown.colRange(texels, texels + mask.cols).clone();
}

// Per-channel median of the texels of `map` (CV_32FC3) where `mask` is set; nullopt if none.
std::optional<glm::vec3> medianWhere(const cv::Mat& map, const cv::Mat& mask) {
    std::array<std::vector<float>, 3> v;
    for (int y = 0; y < map.rows; ++y)
        for (int x = 0; x < map.cols; ++x)
            if (mask.at<uint8_t>(y, x))
                for (int c = 0; c < 3; ++c) v[size_t(c)].push_back(map.at<cv::Vec3f>(y, x)[c]);
    if (v[0].empty()) return std::nullopt;
    glm::vec3 m;
    for (int c = 0; c < 3; ++c) {
        auto& ch = v[size_t(c)];
        std::nth_element(ch.begin(), ch.begin() + long(ch.size() / 2), ch.end());
        m[c] = ch[ch.size() / 2];
    }
    return m;
}

cv::Mat withAlpha(const cv::Mat& rgb, const cv::Mat& seen) {
    cv::Mat alpha, out;
    seen.convertTo(alpha, CV_32F, 1.0 / 255.0);
    cv::merge(std::vector<cv::Mat>{rgb, alpha}, out);
    return out;
}

}  // namespace

bool EnvironmentLightFinder::lookupValid(const CameraIntrinsics& K, double reachDeg, const Pose& T,
                                         int width) const {
    return width_ == width && reachDeg_ == reachDeg && K.width == camera_.width &&
           K.height == camera_.height && K.fx == camera_.fx && K.fy == camera_.fy &&
           K.cx == camera_.cx && K.cy == camera_.cy && K.model == camera_.model &&
           K.distortion == camera_.distortion && K.maxFisheyeTheta == camera_.maxFisheyeTheta &&
           T.rotation == pose_.rotation && T.translation == pose_.translation;
}

EnvironmentLightSplit EnvironmentLightFinder::find(const cv::Mat& bgr, const CameraIntrinsics& K,
                                                   double reachDeg, const Pose& T,
                                                   const glm::vec3& gain, int width,
                                                   const LightEstimationOptions& options) {
    if (bgr.empty() || bgr.type() != CV_8UC3 || bgr.cols != K.width || bgr.rows != K.height)
        throw Error(fmt::format(
            "environment lights: the frame is {}x{} (type {}), the camera's calibration {}x{} "
            "8-bit BGR",
            bgr.cols, bgr.rows, bgr.type(), K.width, K.height));
    if (width < 8 || width % 2) throw Error("environment lights: map width must be even, >= 8");
    const int W = width, H = width / 2;
    if (!lookupValid(K, reachDeg, T, width)) {
        lookup_ = equirectLookup(K, T, W, H, reachDeg, /*fill=*/true);
        camera_ = K;
        reachDeg_ = reachDeg;
        pose_ = T;
        width_ = width;
    }

    // 1. The frame in scene radiance (linear RGB), and the map as the camera saw it.
    std::array<cv::Vec3f, 256> lut;
    for (int v = 0; v < 256; ++v) {
        const float l = srgbToLinear(float(v) / 255.0f);
        lut[size_t(v)] = cv::Vec3f(l * gain.r, l * gain.g, l * gain.b);
    }
    // Reused between frames: the first touch of fresh pages costs more than the work.
    linear_.create(bgr.rows, bgr.cols, CV_32FC3);
    cv::Mat& linear = linear_;
    for (int y = 0; y < bgr.rows; ++y) {
        const cv::Vec3b* in = bgr.ptr<cv::Vec3b>(y);
        cv::Vec3f* out = linear.ptr<cv::Vec3f>(y);
        for (int x = 0; x < bgr.cols; ++x)
            out[x] = cv::Vec3f(lut[in[x][2]][0], lut[in[x][1]][1], lut[in[x][0]][2]);
    }
    cv::Mat map;
    cv::remap(linear, map, lookup_.mapX, lookup_.mapY, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    EnvironmentLightSplit out;
    out.map = withAlpha(map, lookup_.seen);
    double seenOmega = 0, allOmega = 0;
    for (int y = 0; y < H; ++y) {
        const double w = std::cos(M_PI / 2 - M_PI * (y + 0.5) / H);
        allOmega += w * W;
        seenOmega += w * cv::countNonZero(lookup_.seen.row(y));
    }
    out.seenFraction = float(seenOmega / allOmega);

    // 2. The lights.
    cv::Mat regions;
    out.lights = estimateLights(out.map, options, &regions);
    if (out.lights.empty()) {
        out.lightFree = out.map.clone();
        const std::vector<glm::vec3> sh = GpuScene::projectEquirectToSH(map, 1.0f, 0.0);
        std::copy(sh.begin(), sh.end(), out.lightFreeSH.begin());
        return out;
    }

    // 3. Each light's region (grown by a texel) painted over in the frame with its surroundings.
    const cv::Mat seen = lookup_.seen;
    cv::Mat anyRegion = (regions >= 0) & seen;
    painted_.create(bgr.rows, bgr.cols, CV_8U);
    painted_.setTo(0);
    cv::Mat& painted = painted_;  // light index + 1
    const auto allSeen = medianWhere(map, seen);
    for (size_t k = 0; k < out.lights.size(); ++k) {
        const cv::Mat region = (regions == int(k)) & seen;
        const cv::Mat grown = dilateWrapped(region, 1) & seen;
        const cv::Mat ring = dilateWrapped(region, 3) & ~dilateWrapped(anyRegion, 1) & seen;
        const glm::vec3 fill = medianWhere(map, ring).value_or(allSeen.value_or(glm::vec3(0)));
        out.fill.push_back(fill);
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                if (!grown.at<uint8_t>(y, x)) continue;
                const cv::Point2f p(lookup_.mapX.at<float>(y, x), lookup_.mapY.at<float>(y, x));
                // The texel's footprint in the image: the farthest of its neighbours' positions.
                float radius = 1.0f;
                const int nx[4] = {(x + 1) % W, (x + W - 1) % W, x, x};
                const int ny[4] = {y, y, std::min(y + 1, H - 1), std::max(y - 1, 0)};
                for (int n = 0; n < 4; ++n) {
                    if (!seen.at<uint8_t>(ny[n], nx[n])) continue;
                    const cv::Point2f q(lookup_.mapX.at<float>(ny[n], nx[n]),
                                        lookup_.mapY.at<float>(ny[n], nx[n]));
                    radius = std::max(radius, float(cv::norm(p - q)));
                }
                cv::circle(painted, cv::Point(int(std::lround(p.x)), int(std::lround(p.y))),
                           int(std::ceil(radius)) + 1, cv::Scalar(double(k + 1)), cv::FILLED);
            }
    }
    // The frame as the camera saw it is not needed any more: painted over in place.
    for (int y = 0; y < bgr.rows; ++y) {
        const uint8_t* p = painted.ptr<uint8_t>(y);
        cv::Vec3f* l = linear.ptr<cv::Vec3f>(y);
        for (int x = 0; x < bgr.cols; ++x)
            if (p[x] > 0) {
                const glm::vec3& f = out.fill[size_t(p[x] - 1)];
                l[x] = cv::Vec3f(f.r, f.g, f.b);
            }
    }
    cv::Mat lightFree;
    cv::remap(linear, lightFree, lookup_.mapX, lookup_.mapY, cv::INTER_LINEAR,
              cv::BORDER_REPLICATE);
    out.lightFree = withAlpha(lightFree, seen);

    // 4. Each light's irradiance: what was taken out of the seen texels whose bilinear taps
    // touch its painted pixels.
    std::vector<glm::dvec3> removed(out.lights.size(), glm::dvec3(0.0));
    for (int y = 0; y < H; ++y) {
        const double lat = M_PI / 2 - M_PI * (y + 0.5) / H;
        const double dOmega = std::cos(lat) * (M_PI / H) * (2 * M_PI / W);
        for (int x = 0; x < W; ++x) {
            if (!seen.at<uint8_t>(y, x)) continue;
            const float px = lookup_.mapX.at<float>(y, x), py = lookup_.mapY.at<float>(y, x);
            const int x0 = std::clamp(int(std::floor(px)), 0, bgr.cols - 1);
            const int y0 = std::clamp(int(std::floor(py)), 0, bgr.rows - 1);
            int label = 0;
            for (int t = 0; t < 4 && !label; ++t)
                label = painted.at<uint8_t>(std::min(y0 + t / 2, bgr.rows - 1),
                                            std::min(x0 + t % 2, bgr.cols - 1));
            if (!label) continue;
            const cv::Vec3f a = map.at<cv::Vec3f>(y, x), b = lightFree.at<cv::Vec3f>(y, x);
            removed[size_t(label - 1)] +=
                glm::dvec3(a[0] - b[0], a[1] - b[1], a[2] - b[2]) * dOmega;
        }
    }
    for (size_t k = 0; k < out.lights.size(); ++k)
        out.lights[k].irradiance = glm::max(glm::vec3(removed[k]), glm::vec3(0.0f));

    // 5. The diffuse light of the environment without them.
    const std::vector<glm::vec3> sh = GpuScene::projectEquirectToSH(lightFree, 1.0f, 0.0);
    std::copy(sh.begin(), sh.end(), out.lightFreeSH.begin());
    return out;
}

}  // namespace mirage::render
