#pragma once
// Ground truth for mixed reality by differential rendering (Debevec 1998; Knecht et al. 2013,
// Eqs. 1-2): render the scene twice — L_rv with everything, L_r with only its REAL parts (real
// geometry as the only occluders, real lights, the real environment) — and add the difference the
// virtual objects make to the camera image:
//     dL = L_rv - L_r,  L_final = CI + alpha * dL  with alpha = CI / L_r   (real pixels)
//     L_final = L_rv                                                      (virtual pixels)
// blended by the fraction of each pixel covered by virtual objects (anti-aliased edges).
// Every image here is linear RGB float (CV_32FC3).
#include <opencv2/core.hpp>

#include "render/raytrace/ReferenceRenderer.h"

namespace mirage::raytrace {

struct DifferentialImages {
    cv::Mat realOnly;         // L_r, CV_32FC3 linear
    cv::Mat realAndVirtual;   // L_rv, CV_32FC3 linear
    cv::Mat virtualCoverage;  // CV_32F in [0,1], from the L_rv render
    RenderResult realStats, mixedStats;
};

// Renders L_r and L_rv of `scene` for one camera with the same settings and seed.
DifferentialImages renderDifferential(const Scene& scene, const EmbreeDevice& device,
                                      const RenderCamera& camera, const RenderSettings& settings,
                                      const ProgressCallback& progress = {});

// Eq. 1-2 per pixel and channel. alpha = (CI + eps) / (L_r + eps) keeps dark real pixels stable
// (where L_r -> 0, alpha -> 1 and the difference is added unscaled); it is clamped to
// [0, maxAlpha]. `cameraImage` is linear RGB float of the same size.
cv::Mat compositeDifferential(const cv::Mat& cameraImage, const DifferentialImages& images,
                              float eps = 1e-3f, float maxAlpha = 16.0f);

}  // namespace mirage::raytrace
