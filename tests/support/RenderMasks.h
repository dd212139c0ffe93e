#pragma once
// Masks for render tests: where two renders differ, and where a box is seen (implemented in
// TestSupport.cpp).
#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"

namespace mirage::test {

// Pixels where two linear renders differ (any channel sum above 1e-6), CV_8U 255 / 0.
cv::Mat changedPixels(const cv::Mat& a, const cv::Mat& b);
// The silhouette of the axis-aligned box [lo, hi] (world, metres) seen by a pinhole camera at
// T_world_camera: the convex hull of its projected corners (distortion ignored), dilated by 1 px
// for the renderer's rounding to canvas pixels; CV_8U 255 inside, camera-sized.
cv::Mat boxSilhouette(const CameraIntrinsics& camera, const Pose& T_world_camera,
                      const glm::vec3& lo, const glm::vec3& hi);

}  // namespace mirage::test
