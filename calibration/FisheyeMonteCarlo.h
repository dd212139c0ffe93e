#pragma once
// Monte-Carlo check of fish-eye calibration out to the rim (docs/calibration.md, "Fish-eye to the
// rim"). One draw: an ideal equidistant or equisolid lens with a 160-190 degree field at 640x480,
// chessboard views rendered through it (half anywhere in the image, half toward the rim of the
// image circle), blurred in linear light and with sensor noise, detected, and calibrated by
// mirage and by OpenCV's cv::fisheye::calibrate on the same detected corners. Both models are
// compared with the true lens over directions up to 80 degrees off-axis, and mirage's stated
// uncertainty (its covariance carried to those projections) with its true error.
// Used by the `fisheye_montecarlo` benchmark and a small unit test.
#include <string>

#include "calibration/SyntheticViews.h"

namespace mirage::calib {

struct FisheyeDrawOptions {
    int views = 20;
    int width = 640, height = 480;
    double minFovDeg = 160, maxFovDeg = 190;
    double minBlurPx = 0.3, maxBlurPx = 1.0;  // Gaussian sigma, linear light
    double minNoise = 1.0, maxNoise = 3.0;    // sensor noise sigma, 8-bit levels
    double compareUpToDeg = 80;               // directions compared with the true lens
    int supersample = 3;
};

struct FisheyeDraw {
    unsigned seed = 0;
    FisheyeLens lens = FisheyeLens::Equidistant;
    double fovDeg = 0, blurPx = 0, noiseLevels = 0;
    int viewsRendered = 0, viewsDetected = 0, fallbackViews = 0, viewsUsed = 0;
    int droppedCorners = 0;
    double reachDeg = 0;  // mirage's stated reach
    // Projection difference from the true lens (pixels) over directions 0..compareUpToDeg:
    // mean and maximum; OpenCV's mean is NaN when cv::fisheye::calibrate failed.
    double mirageMeanPx = 0, mirageMaxPx = 0, opencvMeanPx = 0;
    // mirage's stated 1-sigma of the projection (RMS 2D error, mean over the same directions).
    double statedStdPx = 0;
    bool reliable = false;
    std::string error;  // set when mirage threw (no result)
};

// One draw, deterministic for a seed (the lens alternates with the seed's parity: odd =
// equisolid). Rendering and detection dominate the time (~5-20 s per draw on this machine).
FisheyeDraw runFisheyeDraw(unsigned seed, const FisheyeDrawOptions& options = {});

const char* fisheyeLensName(FisheyeLens lens);

}  // namespace mirage::calib
