// Fuzz target: calibration files (OpenCV FileStorage YAML, core/camera/CalibrationFile.h).
#include "core/Error.h"
#include "core/camera/CalibrationFile.h"
#include "tests/fuzz/FuzzTarget.h"

namespace mirage::fuzz {
namespace {

bool run(const uint8_t* data, size_t size) {
    const auto path = writeScratch("camera.yaml", data, size);
    try {
        const CameraCalibration c = loadCalibration(path);
        (void)c.intrinsics.width;
        return true;
    } catch (const Error&) {
        return false;
    }
}

}  // namespace

const Target& target() {
    static const Target t{"calibration_fuzz",
                          {".yaml", ".yml"},
                          {"camera_matrix: !!opencv-matrix\n",
                           "distortion_coefficients: ",
                           "image_width: ",
                           "image_height: ",
                           "rows: ",
                           "cols: ",
                           "dt: d\n",
                           "dt: f\n",
                           "dt: u\n",
                           "data: [ ",
                           " ]\n",
                           "fisheye_model: 1\n",
                           "distortion_model: ",
                           "T_parent_camera: !!opencv-matrix\n",
                           "extrinsic_parent: main\n",
                           "reliable: 0\n",
                           "%YAML:1.0\n---\n",
                           "nan",
                           ".inf",
                           "-.inf",
                           "1e308",
                           "!!opencv-matrix",
                           "\n   ",
                           ":",
                           "{",
                           "}",
                           "[",
                           "]",
                           "\"",
                           "'"},
                          run};
    return t;
}

}  // namespace mirage::fuzz
