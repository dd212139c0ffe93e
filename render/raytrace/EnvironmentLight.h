#pragma once
// Environment light: an equirectangular (latitude-longitude) linear RGB image of radiance over
// world directions, importance sampled by a piecewise-constant 2D distribution (pixel max
// component x sin(theta)). Lookups are nearest-pixel so the sampling pdf is exactly proportional
// to what is returned (exact MIS weights).
//
// Mapping (docs/reference-renderer.md): world frame glTF (+Y up). After undoing the rotation
// about +Y, direction l maps to u = 0.5 + atan2(l.x, -l.z) / (2 pi), v = acos(l.y) / pi, with
// (u, v) = (0, 0) the top-left corner: the image centre looks down -Z at the horizon, the top
// row is straight up.
#include <opencv2/core.hpp>

#include <glm/glm.hpp>

#include "render/raytrace/Sampling.h"

namespace mirage::raytrace {

class EnvironmentLight {
public:
    // `linearRgb` CV_32FC3 (R, G, B); `scale` multiplies it; `rotationYDeg` rotates the map about
    // world +Y (positive = counter-clockwise seen from above). Throws mirage::Error on an empty
    // image or non-finite / negative pixels.
    EnvironmentLight(const cv::Mat& linearRgb, float scale, double rotationYDeg);

    glm::vec3 radiance(const glm::vec3& dirWorld) const;
    // Samples a world direction; returns its radiance and solid-angle pdf (0 = failed).
    glm::vec3 sample(glm::vec2 u, glm::vec3& dirWorld, float& pdf) const;
    float pdf(const glm::vec3& dirWorld) const;
    // Total power scale: the average radiance over the sphere (for photon/light budgeting).
    float averageRadiance() const { return averageRadiance_; }

    glm::vec2 directionToUv(const glm::vec3& dirWorld) const;
    glm::vec3 uvToDirection(glm::vec2 uv) const;

private:
    glm::vec3 texel(glm::vec2 uv) const;

    cv::Mat image_;  // CV_32FC3, already scaled
    Distribution2D distribution_;
    float cosRot_ = 1.0f, sinRot_ = 0.0f;
    float averageRadiance_ = 0.0f;
};

}  // namespace mirage::raytrace
