#pragma once
// How the renderer matches the real camera (docs/realtime-renderer.md, "Camera and lens"):
// it renders UNDISTORTED (an ideal pinhole with the calibrated fx, fy) onto a canvas large
// enough to hold every ray the distorted image sees, and the compositor then DISTORTS: for each
// output (camera) pixel it looks up the undistorted canvas position of that pixel's ray
// (CameraIntrinsics::unproject), precomputed once into a remap table.
//
// Pixel convention (OpenCV): pixel (0,0) is the centre of the top-left pixel, so the image spans
// u in [-0.5, width-0.5]. Images in GL are kept top-row-first in memory: GL window row 0 is the
// image's top row (v = 0), so readbacks are directly cv::Mat-ordered.
#include <vector>

#include <glm/glm.hpp>

#include "core/camera/CameraModel.h"

namespace mirage::render {

struct CameraProjection {
    CameraIntrinsics camera;  // the real camera (output size, distortion)
    // The undistorted render canvas: same focal lengths, principal point shifted by the margin.
    int canvasWidth = 0, canvasHeight = 0;
    double canvasCx = 0, canvasCy = 0;
    bool hasDistortion = false;
    // For every output pixel (row-major, top row first): canvas pixel coordinates (OpenCV
    // convention) of its ray, or (-1e4, -1e4) where the model cannot unproject it.
    std::vector<glm::vec2> remap;

    // Builds the canvas and remap for `camera`. Canvas growth is capped at `maxGrowth` times the
    // image size per axis (a wide fish-eye cannot be rendered as one pinhole image; rays beyond
    // the cap are left black). Throws mirage::Error on invalid intrinsics.
    static CameraProjection make(const CameraIntrinsics& camera, double maxGrowth = 2.0);

    // OpenCV camera frame -> GL clip space for the canvas; depth range [near, far] metres.
    glm::mat4 projectionMatrix(float nearM, float farM) const;
    // Point in the OpenCV camera frame -> canvas pixel (undistorted pinhole).
    glm::dvec2 projectToCanvas(const glm::dvec3& pointCamera) const;
    // For every canvas pixel (row-major, top row first): the camera-image pixel (OpenCV
    // convention, lens distortion applied) that sees its ray, (-1e4, -1e4) where none does.
    // What back-projection into the video (Knecht 2013 Eqs. 8-10) looks up.
    std::vector<glm::vec2> canvasToCameraTable() const;
};

}  // namespace mirage::render
