#include "render/raytrace/DifferentialRendering.h"

#include <algorithm>

#include "core/Error.h"

namespace mirage::raytrace {

DifferentialImages renderDifferential(const Scene& scene, const EmbreeDevice& device,
                                      const RenderCamera& camera, const RenderSettings& settings,
                                      const ProgressCallback& progress) {
    DifferentialImages out;
    const int total = 2 * settings.samplesPerPixel;
    {
        RayTracingScene real(scene, SceneSubset::RealOnly, device);
        out.realStats = render(real, camera, settings, [&](int done, int, double s) {
            if (progress) progress(done, total, s);
        });
    }
    double realSeconds = out.realStats.seconds;
    int realPasses = out.realStats.passes;
    {
        RayTracingScene all(scene, SceneSubset::All, device);
        out.mixedStats = render(all, camera, settings, [&](int done, int, double s) {
            if (progress) progress(realPasses + done, total, realSeconds + s);
        });
    }
    out.realOnly = out.realStats.radiance;
    out.realAndVirtual = out.mixedStats.radiance;
    out.virtualCoverage = out.mixedStats.virtualCoverage;
    return out;
}

cv::Mat compositeDifferential(const cv::Mat& cameraImage, const DifferentialImages& images,
                              float eps, float maxAlpha) {
    const cv::Mat& lr = images.realOnly;
    const cv::Mat& lrv = images.realAndVirtual;
    if (cameraImage.type() != CV_32FC3 || cameraImage.size() != lr.size() ||
        lrv.size() != lr.size() || images.virtualCoverage.size() != lr.size())
        throw Error(
            "differential composite: the camera image must be linear RGB float (CV_32FC3) of the "
            "rendered size " +
            std::to_string(lr.cols) + "x" + std::to_string(lr.rows));
    cv::Mat out(lr.size(), CV_32FC3);
    for (int y = 0; y < lr.rows; ++y)
        for (int x = 0; x < lr.cols; ++x) {
            const auto& ci = cameraImage.at<cv::Vec3f>(y, x);
            const auto& r = lr.at<cv::Vec3f>(y, x);
            const auto& rv = lrv.at<cv::Vec3f>(y, x);
            float m = std::clamp(images.virtualCoverage.at<float>(y, x), 0.0f, 1.0f);
            cv::Vec3f v;
            for (int k = 0; k < 3; ++k) {
                float c = std::max(0.0f, ci[k]);
                float alpha = std::clamp((c + eps) / (std::max(0.0f, r[k]) + eps), 0.0f, maxAlpha);
                float real = std::max(0.0f, c + alpha * (rv[k] - r[k]));
                v[k] = (1.0f - m) * real + m * rv[k];
            }
            out.at<cv::Vec3f>(y, x) = v;
        }
    return out;
}

}  // namespace mirage::raytrace
