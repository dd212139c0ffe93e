#pragma once
// The environment (fish-eye) camera as a live light source (docs/environment.md): what the
// renderer needs to turn its frames into the environment light. Its pose comes from the
// calibration's extrinsics: fixed in the world (T_world_camera), or mounted on the main camera
// (T_main_camera, so that per frame T_world_env = T_world_main * T_main_env with the main
// camera's tracked pose).
#include <filesystem>
#include <optional>

#include <glm/glm.hpp>

#include "core/camera/CalibrationFile.h"
#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"

namespace mirage::render {

struct EnvironmentCameraSetup {
    CameraIntrinsics intrinsics;
    // Largest angle off the optical axis (degrees) the calibration's data reached; beyond it the
    // model is extrapolated and the map is filled instead. <= 0: unknown (the model's limit).
    double reachDeg = -1.0;
    // Exactly one of the two is set.
    std::optional<Pose> T_world_camera;  // fixed in the world (OpenCV camera axes)
    std::optional<Pose> T_main_camera;   // mounted on the main camera
    // Linearised environment-camera pixel -> scene radiance, per channel (R, G, B): the inverse
    // of its exposure, times the white balance that maps its colours onto the main camera's.
    glm::vec3 gain{1.0f};

    // From an environment camera's calibration file (`file` names it in messages). Throws
    // mirage::FileError when the calibration has no usable extrinsic pose (none, or a parent
    // other than "world" / "main") or invalid intrinsics.
    static EnvironmentCameraSetup fromCalibration(const CameraCalibration& calibration,
                                                  const std::filesystem::path& file);
    // The camera's pose when the main camera is at T_world_main.
    Pose poseInWorld(const Pose& T_world_main) const;
};

}  // namespace mirage::render
