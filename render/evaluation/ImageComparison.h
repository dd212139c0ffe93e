#pragma once
// Image error figures for judging a composite against its ground truth (DESIGN.md, "Ground truth,
// and how every effect is judged"): PSNR and SSIM over the whole frame and over a mask (the pixels
// the virtual objects influence). Images are compared as the camera delivers them: 8-bit BGR,
// sRGB-encoded (peak 255), so an error figure means the same as it would on real footage.
//
// Figures over several frames are pooled (ErrorAccumulator): PSNR from the mean squared error of
// all counted pixels of all frames, SSIM as the mean of the per-pixel SSIM map over them, so a
// frame where the virtual object covers few pixels weighs little.
#include <limits>

#include <opencv2/core.hpp>

#include "core/image/ImageCompare.h"  // psnr, ssim, ssimMap: the per-image figures

namespace mirage::render {

// Sums over frames for pooled figures.
struct ErrorAccumulator {
    double squaredError = 0.0;  // sum over counted pixels and channels, in peak-relative units
    double ssimSum = 0.0;       // sum of the per-pixel SSIM (mean over channels)
    double pixels = 0.0;        // counted pixels
    int channels = 3;

    // Adds one frame (mask: CV_8U, nonzero = counted; empty = every pixel).
    void add(const cv::Mat& got, const cv::Mat& truth, double peak, const cv::Mat& mask = {});
    double psnrDb() const;  // +inf if no error, NaN if nothing was counted
    double meanSsim() const;
};

// The four figures every composite is judged by.
struct CompositeError {
    double psnrFrame = std::numeric_limits<double>::quiet_NaN();
    double ssimFrame = std::numeric_limits<double>::quiet_NaN();
    double psnrInfluenced = std::numeric_limits<double>::quiet_NaN();
    double ssimInfluenced = std::numeric_limits<double>::quiet_NaN();
    double influencedPixels = 0;  // summed over frames
};

struct CompositeErrorAccumulator {
    ErrorAccumulator frame, influenced;
    // got, truth: 8-bit BGR sRGB of equal size; influence: CV_8U (nonzero = the virtual objects
    // change the pixel), same size.
    void add(const cv::Mat& gotSrgb8, const cv::Mat& truthSrgb8, const cv::Mat& influence);
    void merge(const CompositeErrorAccumulator& other);  // adds another's sums (frames pooled)
    CompositeError result() const;
};

}  // namespace mirage::render
