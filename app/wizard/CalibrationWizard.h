#pragma once
// The calibration wizard window (GLFW + Dear ImGui). It only displays: all decisions are made by
// calibration::CalibrationSession (docs/calibration.md, "Wizard").
#include <string>
#include <vector>

#include "core/camera/CameraModel.h"

namespace mirage::app {

struct WizardOptions {
    std::vector<std::string> inputs;  // images, folders or videos (replayed frame by frame)
    std::string cameraDevice;         // live V4L2 device, e.g. /dev/video0 (when no inputs)
    std::string board;                // as for --batch
    std::string output;               // where "Save" writes (OpenCV YAML)
    DistortionModel model = DistortionModel::BrownConrady;
    bool fixK3 = false;
    // Headless documentation/testing: after this many frames (0 = the whole input) save a PNG of
    // the window to `screenshot` and exit.
    std::string screenshot;
    int screenshotAfterFrames = 0;
};

// Runs until the window is closed (or the screenshot is taken). Returns the exit code: 0 when a
// reliable calibration was saved or nothing was saved, 2 when the saved one is marked
// unreliable. Throws mirage::Error without a display or with bad inputs.
int runCalibrationWizard(const WizardOptions& options);

}  // namespace mirage::app
