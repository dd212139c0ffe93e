#pragma once
// Image error figures for judging a composite against its ground truth (docs/bench.md): PSNR and
// SSIM over the whole frame and over a mask (the pixels the virtual objects influence). Images are
// compared as the camera delivers them: 8-bit BGR, sRGB-encoded (peak 255), so an error figure
// means the same as it would on real footage.
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
    // Over the edge pixels of what the virtual objects change (edgePixels): their silhouettes
    // and their shadows' edges, where aliasing shows (docs/camera-matching.md, "Anti-aliasing").
    double psnrEdges = std::numeric_limits<double>::quiet_NaN();
    double edgePixels = 0;  // summed over frames
};

// The edge pixels of the virtual objects' contribution, from the ground truth alone (so every
// configuration is judged over the same pixels): influenced pixels where the ground truth's
// change to the footage (truth - footage, linear luminance) varies by more than `threshold`
// (linear camera units) within the pixel's 3x3 neighbourhood. CV_8U 255 / 0.
cv::Mat edgePixels(const cv::Mat& footageSrgb8, const cv::Mat& truthSrgb8, const cv::Mat& influence,
                   double threshold = 0.05);

struct CompositeErrorAccumulator {
    ErrorAccumulator frame, influenced, edges;
    // got, truth: 8-bit BGR sRGB of equal size; influence: CV_8U (nonzero = the virtual objects
    // change the pixel), same size; edges: CV_8U (edgePixels), same size, or empty (none counted).
    void add(const cv::Mat& gotSrgb8, const cv::Mat& truthSrgb8, const cv::Mat& influence,
             const cv::Mat& edges = {});
    void merge(const CompositeErrorAccumulator& other);  // adds another's sums (frames pooled)
    CompositeError result() const;
};

}  // namespace mirage::render
