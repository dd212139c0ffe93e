#pragma once
// The camera response from an exposure bracket (docs/camera-matching.md, "Camera response"):
// several pictures of the same still scene taken at known exposure times, fitted with Debevec &
// Malik's method (SIGGRAPH 1997, OpenCV's CalibrateDebevec). The result is the inverse response
// per channel (core/camera/CameraResponse.h), stored in the camera's calibration file.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/camera/CameraResponse.h"

namespace mirage::calibration {

struct BracketImage {
    cv::Mat bgr8;            // 8-bit BGR, as the camera delivers it
    double exposureSeconds;  // its exposure time (any consistent unit)
    std::string name;        // for messages (a file name)
};

struct ResponseFit {
    CameraResponse response;
    // The gamma whose power curve is closest to the fitted one over codes 16..239 (least squares
    // in log space, the three channels together): a one-number summary (2.2 for sRGB-like).
    double equivalentGamma = 0.0;
    // How well the bracket agrees with the fitted curve: the RMS spread (natural log) of the
    // per-image radiance estimates of the sampled pixels, well-exposed samples only. A still
    // scene and a right response give ~0.02-0.05; a moving scene or wrong times give more.
    double logRadianceSpread = 0.0;
    int samplesUsed = 0;
};

// Throws mirage::Error naming the image when the bracket cannot give a response: fewer than 3
// images, different sizes or types, exposure times not finite and positive, fewer than 3
// distinct times, or too little of the code range covered (the scene too dark or too flat).
ResponseFit fitCameraResponse(const std::vector<BracketImage>& bracket, int samples = 200,
                              float smoothness = 10.0f);

}  // namespace mirage::calibration
