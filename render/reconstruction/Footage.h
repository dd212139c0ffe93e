#pragma once
// What the reconstruction of the real proxies works from (docs/reconstruction.md): the main
// camera's frames with their tracked poses, the camera's calibration, and the tag board's plane.
// The caller tracks (tracking::Tracker, a poses CSV or a session's ground truth) and keeps only
// frames whose pose is trusted (tracking state ok); this library never tracks.
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include "core/Error.h"
#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"

namespace mirage::reconstruction {

struct PosedFrame {
    int index = 0;        // frame number in the session
    double t = 0;         // seconds
    cv::Mat bgr;          // 8-bit BGR, sRGB-encoded, as the camera delivered it
    Pose T_world_camera;  // OpenCV camera axes, metres
};

// The board's plane in the world: the table it lies on. `point` is the board's centre, `normal`
// the plane's unit normal out of the table (up), `axisU` a unit vector in the plane (the board's
// +X); axisV = cross(normal, axisU). halfU, halfV: the board's half extents along them (metres),
// the part of the plane known to be flat before any footage is read.
struct BoardPlane {
    glm::dvec3 point{0.0};
    glm::dvec3 normal{0.0, 1.0, 0.0};
    glm::dvec3 axisU{1.0, 0.0, 0.0};
    double halfU = 0.1, halfV = 0.1;
    glm::dvec3 axisV() const { return glm::cross(normal, axisU); }
    // Plane coordinates of a world point: (u, v, height above the plane), metres.
    glm::dvec3 toPlane(const glm::dvec3& world) const {
        const glm::dvec3 d = world - point;
        return {glm::dot(d, axisU), glm::dot(d, axisV()), glm::dot(d, normal)};
    }
    glm::dvec3 toWorld(const glm::dvec3& uvh) const {
        return point + uvh.x * axisU + uvh.y * axisV() + uvh.z * normal;
    }
};

struct Footage {
    CameraIntrinsics camera;  // main camera; pinhole (Brown-Conrady) distortion is undone
    std::vector<PosedFrame> frames;
    BoardPlane board;
    // Linear radiance -> linear camera value (the replay's exposure; 1 for synthetic footage).
    double exposure = 1.0;
};

}  // namespace mirage::reconstruction
