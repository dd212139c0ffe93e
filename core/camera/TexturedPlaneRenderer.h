#pragma once
// What a camera sees of a flat printed pattern (a chessboard, a tag board's sheet): the one
// renderer behind the synthetic views of tracking and calibration tests, benchmarks and
// `mirage calibrate --write-synthetic`.
//
// Every output pixel is split into supersample x supersample sub-pixels, each jittered inside
// its cell (a deterministic hash, so edges aligned with the pixel grid are not quantised to
// 1/supersample steps). Each sub-pixel is unprojected with the camera model (pinhole
// Brown-Conrady or Kannala-Brandt fish-eye, CameraIntrinsics::unproject), the ray is intersected
// with the pattern's plane and the texture is sampled there, in linear light. The sub-pixels of a
// pixel are averaged in linear light, and the mean is encoded to sRGB: a box filter over the
// pixel's area as a camera sensor integrates it. Pixel (0,0) is the centre of the top-left pixel
// (OpenCV; pixel (x, y) covers [x - 0.5, x + 0.5] x [y - 0.5, y + 0.5]).
//
// Camera rays are unprojected exactly on a coarse grid (every 4 sub-pixels) and interpolated
// bilinearly in between (the lens mapping is smooth: the interpolated rays land within 2e-3 px
// of the exact ones, 95 degrees off-axis included, tests/core/TexturedPlaneRenderer_test.cpp);
// cells touching a ray outside the model's field of view are unprojected per sub-pixel.
#include <opencv2/core.hpp>

#include <glm/glm.hpp>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"

namespace mirage {

// A pattern in the plane z = 0 of its own frame (metres).
struct PlaneTexture {
    cv::Mat image;  // CV_8UC1, sRGB-encoded grey; row 0 at the smallest plane y
    double metresPerTexelX = 0, metresPerTexelY = 0;
    // Plane-frame (x, y) of the outer corner of texel (0, 0): texel (u, v) covers
    // [x0 + u*mx, x0 + (u+1)*mx) x [y0 + v*my, y0 + (v+1)*my).
    glm::dvec2 originMetres{0.0, 0.0};
    // Nearest: exact for patterns whose edges lie on texel edges (a chessboard at one texel per
    // square). Bilinear: for rasterised artwork finer than a sub-pixel (a tag board's sheet).
    enum class Filter { Nearest, Bilinear } filter = Filter::Bilinear;
};

// Output levels, sRGB-encoded 8-bit values. Texture value 0 shows as `black`, 255 as `white`,
// mixing in linear light (ink and paper); rays that miss the texture show `background`.
struct PlaneShading {
    double black = 0, white = 255, background = 110;
};

class TexturedPlaneRenderer {
public:
    // Throws mirage::Error if the intrinsics are invalid or supersample < 1.
    explicit TexturedPlaneRenderer(const CameraIntrinsics& camera, int supersample = 3);

    // 8-bit grey image, sRGB-encoded, camera.width x camera.height. T_camera_plane maps points of
    // the pattern's frame (metres) into the camera frame (OpenCV axes). Throws mirage::Error for
    // an empty or non-8-bit texture or non-positive texel sizes.
    cv::Mat render(const PlaneTexture& texture, const Pose& T_camera_plane,
                   const PlaneShading& shading = {}) const;

    const CameraIntrinsics& camera() const { return camera_; }
    int supersample() const { return n_; }

    // The ray of sub-pixel position `pixel` as the renderer uses it (interpolated, camera frame;
    // pinhole rays scaled to z = 1, fish-eye rays unit length), or nullopt outside the field of
    // view. For tests of the interpolation error.
    std::optional<glm::dvec3> rayAt(const glm::dvec2& pixel) const;

private:
    CameraIntrinsics camera_;
    int n_;
    bool noDistortion_;
    int gridW_ = 0, gridH_ = 0;     // coarse ray grid, one node every kStep sub-pixels
    std::vector<glm::dvec3> grid_;  // rays at the nodes
    std::vector<uint8_t> gridOk_;   // node ray valid
    std::optional<glm::dvec3> exactRay(const glm::dvec2& pixel) const;
    std::optional<glm::dvec3> subPixelRay(double xh, double yh) const;  // sub-pixel units
};

}  // namespace mirage
