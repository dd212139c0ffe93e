#pragma once
// The real light, placed (docs/environment.md, "Light estimation"): the dominant lights of an
// environment-camera frame as directional lights, and the environment without them, so that a
// renderer that places them as shadow-casting lights does not count their energy twice.
//
// Per frame, on the CPU, at a map width of its own (EnvironmentLightFinder::find):
//  1. the frame (8-bit sRGB) is linearised, scaled by the camera's gain into scene radiance and
//     resampled onto an equirectangular map with the mapping and fill of
//     core/camera/EquirectProjection.h (the environment pass's mapping on the GPU);
//  2. the lights are found on it (render/LightEstimation.h);
//  3. each light's region, grown by one texel (the bilinear halo), is painted over in the frame
//     itself with the region's surrounding level (the per-channel median of the seen texels 2-3
//     texels around it), and the frame is resampled again: the light-free map, in which the
//     mirrored copy the fill made of the light (the unseen part) is gone as well;
//  4. each light's irradiance is what was taken out of the seen part of the map (the sum of
//     (L - L_light-free) dOmega over the texels whose source pixels were painted), so the map
//     without the light plus the light hold the energy of the map as the camera saw it;
//  5. the light-free map is projected onto SH9 (GpuScene::projectEquirectToSH): the diffuse
//     environment light of a renderer that places the lights.
#include <array>
#include <vector>

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/camera/EquirectProjection.h"
#include "core/math/Pose.h"
#include "render/LightEstimation.h"

namespace mirage::render {

struct EnvironmentLightSplit {
    // Strongest first. direction and share as estimateLights() gives them; irradiance (W/m^2 per
    // channel at normal incidence) is the energy taken out of the map (step 4 above).
    std::vector<EstimatedLight> lights;
    std::vector<glm::vec3> fill;  // per light: the radiance its region was painted with
    cv::Mat map;                  // CV_32FC4 scene radiance as the camera saw it; alpha 1 = seen
    cv::Mat lightFree;            // CV_32FC4 the same without the lights
    std::array<glm::vec3, 9> lightFreeSH{};  // radiance SH9 of lightFree (world axes)
    float seenFraction = 0.0f;               // solid-angle fraction of the map the camera saw
};

class EnvironmentLightFinder {
public:
    // `frameBgr8`: the environment camera's frame (8-bit BGR, sRGB-encoded, the camera's size);
    // `reachDeg`: the trusted angle off the optical axis (<= 0: the model's limit); `gain`:
    // linear pixel value -> scene radiance per channel (R, G, B); `width`: of the map (height =
    // width / 2). The resampling table is kept while the camera, its pose and the width stay.
    // Throws mirage::Error on a frame of another size or type than the camera's.
    EnvironmentLightSplit find(const cv::Mat& frameBgr8, const CameraIntrinsics& camera,
                               double reachDeg, const Pose& T_world_camera, const glm::vec3& gain,
                               int width, const LightEstimationOptions& options = {});

private:
    bool lookupValid(const CameraIntrinsics& camera, double reachDeg, const Pose& T_world_camera,
                     int width) const;
    EquirectLookup lookup_;
    cv::Mat linear_, painted_;  // per-frame buffers of the camera's size, kept between frames
    CameraIntrinsics camera_;
    double reachDeg_ = 0.0;
    Pose pose_;
    int width_ = 0;
};

}  // namespace mirage::render
