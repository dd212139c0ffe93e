#pragma once
// The real light, found (docs/environment.md, "Light estimation"): the dominant light sources of
// an environment map as directional lights. A light is a bright, compact region of the seen part
// of the map: texels brighter than `brightFactor` x the map's median luminance, joined into
// connected regions (8-neighbours, wrapping around in longitude); a region counts when its solid
// angle is at most `maxSolidAngleSr` and it delivers at least `minShare` of the map's irradiance
// budget. Per region:
//   direction  = the excess-luminance-weighted mean direction (world, unit),
//   irradiance = sum over its texels of (L - L_background) dOmega, per channel (W/m^2 at normal
//                incidence: a glTF directional light's intensity x colour),
// with L_background the median radiance of the seen texels. Filled texels (alpha < 0.5, never seen
// by the camera) are ignored. A uniform environment has no texel above the threshold: no light.
//
// Values are in the map's units (scene radiance), so a camera whose bright pixels clip (8-bit)
// underestimates the irradiance: expose the environment camera for its highlights.
#include <vector>

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

namespace mirage::render {

struct LightEstimationOptions {
    float brightFactor = 4.0f;      // threshold: this many times the median luminance
    float maxSolidAngleSr = 0.25f;  // larger bright regions are sky or walls, not a light
    float minShare = 0.05f;         // of the luminance irradiance of the whole map (cosine-free)
    int maxLights = 4;
};

struct EstimatedLight {
    glm::vec3 direction{0.0f, 1.0f, 0.0f};  // world, unit: where the light is (towards it)
    glm::vec3 irradiance{0.0f};             // W/m^2 per channel at normal incidence
    float solidAngleSr = 0.0f;              // of the region
    float share = 0.0f;                     // of the map's irradiance budget
    // The light as a glTF directional light: colour (max channel 1) and intensity (W/m^2).
    glm::vec3 color() const;
    float intensity() const;
};

// `map`: equirectangular (docs/environment.md layout), CV_32FC3 (all seen) or CV_32FC4 (alpha =
// seen). Strongest first. `regions` (optional) receives the map's texels of each light: CV_32S of
// the map's size, the light's index in the result, -1 elsewhere.
std::vector<EstimatedLight> estimateLights(const cv::Mat& map,
                                           const LightEstimationOptions& options = {},
                                           cv::Mat* regions = nullptr);

}  // namespace mirage::render
