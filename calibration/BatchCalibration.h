#pragma once
// `mirage calibrate --batch`: every frame of the inputs is searched for the target, the views
// found are calibrated, and a report says what was used, what was rejected and why
// (docs/calibration.md, "Report").
#include <string>
#include <vector>

#include "calibration/CalibrationTarget.h"
#include "calibration/Calibrator.h"
#include "core/session/FrameSource.h"

namespace mirage::calib {

struct BatchOptions {
    CalibrationOptions calibration;
    FrameListOptions source;
};

struct SkippedFrame {
    std::string name;
    std::string reason;
};

struct BatchResult {
    cv::Size imageSize;
    std::string targetDescription;
    int framesRead = 0;
    std::vector<SkippedFrame> skipped;  // frames without a usable detection
    CalibrationResult calibration;
};

// Frames come from openFrameList (core/session/FrameSource.h); a lost frame (damaged bytes in
// a recording) is listed as skipped. Throws mirage::Error / FileError on: no or unreadable inputs,
// frames of different sizes (both files named), the target found in no frame, or a calibration that
// produced no finite numbers.
BatchResult runBatchCalibration(const std::vector<std::string>& inputs,
                                const CalibrationTarget& target, const BatchOptions& options);

// Human-readable report: model, image size, RMS, every parameter with its 1-sigma standard
// deviation, per-view errors and tilts, rejected views and skipped frames with reasons, and the
// reliability verdict.
std::string formatReport(const BatchResult& result);
// The calibration part of the report alone (also shown by the wizard).
std::string formatCalibrationResult(const CalibrationResult& result);

}  // namespace mirage::calib
