#pragma once
// The calibration wizard window (GLFW + Dear ImGui). It only displays: all decisions are made by
// calibration::CalibrationSession (docs/calibration.md, "Wizard"). Its stages: the input
// (WizardInput: the next frame that is not lost), the calibration session (UI-free, in
// calibration/), and the window's panels.
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/session/FrameSource.h"

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

// The wizard's frames: the inputs (images, a folder, videos: every frame, since stillness is
// measured between consecutive video frames) or a live camera. A lost frame (damaged bytes in a
// recording) is logged and skipped.
class WizardInput {
public:
    // Throws mirage::Error when the options name no source.
    explicit WizardInput(const WizardOptions& options);
    // The next frame that is not lost (8-bit BGR) and its name ("frame N" where the source
    // names none: a live camera). False at the end of the input.
    bool next(cv::Mat& bgr, std::string& name);
    // Separate photos (no video among the inputs): each a deliberate, still capture.
    bool stillImages() const { return stillImages_; }
    const std::string& description() const { return description_; }

private:
    std::unique_ptr<FrameSource> source_;
    bool stillImages_ = false;
    int index_ = 0;
    std::string description_;
};

// Runs until the window is closed (or the screenshot is taken). Returns the exit code: 0 when a
// reliable calibration was saved or nothing was saved, 2 when the saved one is marked
// unreliable. Throws mirage::Error without a display or with bad inputs.
int runCalibrationWizard(const WizardOptions& options);

}  // namespace mirage::app
