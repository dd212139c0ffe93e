#include "render/EnvironmentCamera.h"

#include "core/Error.h"

namespace mirage::render {

EnvironmentCameraSetup EnvironmentCameraSetup::fromCalibration(const CameraCalibration& c,
                                                               const std::filesystem::path& file) {
    if (!c.intrinsics.isValid())
        throw FileError(file.string(),
                        "the environment camera's intrinsics are invalid (focal lengths and "
                        "image size must be positive); recalibrate it");
    if (!c.T_parent_camera)
        throw FileError(file.string(),
                        "the environment camera's calibration has no extrinsic pose "
                        "(T_parent_camera with parent \"main\" or \"world\"); calibrate its "
                        "extrinsics (docs/calibration.md) to light the scene with it");
    EnvironmentCameraSetup s;
    s.intrinsics = c.intrinsics;
    s.reachDeg = c.reachDeg;
    if (c.extrinsicParent == "world")
        s.T_world_camera = *c.T_parent_camera;
    else if (c.extrinsicParent == "main")
        s.T_main_camera = *c.T_parent_camera;
    else
        throw FileError(file.string(), "the extrinsic pose's parent is \"" + c.extrinsicParent +
                                           "\"; the environment camera needs \"main\" (mounted "
                                           "on the main camera) or \"world\" (fixed)");
    if (!c.T_parent_camera->isFinite())
        throw FileError(file.string(), "the extrinsic pose T_parent_camera is not finite");
    return s;
}

Pose EnvironmentCameraSetup::poseInWorld(const Pose& T_world_main) const {
    if (T_world_camera) return *T_world_camera;
    MR_CHECK(T_main_camera.has_value(), "environment camera without a pose");
    return T_world_main * *T_main_camera;
}

}  // namespace mirage::render
