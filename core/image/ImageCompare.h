#pragma once
// Image error figures: PSNR and SSIM over a whole image or over a mask. One implementation for
// the whole project: the benchmark's composite judging (render/evaluation) and the tests
// (tests/support) both use it. Images are compared in the units they come in; `peak` is the
// signal's maximum (255 for 8-bit, 1 for linear float).
#include <opencv2/core.hpp>

namespace mirage {

// Per-pixel SSIM map (Wang et al. 2004: 11x11 Gaussian window, sigma 1.5, C1 = 0.01², C2 = 0.03²)
// of two images of equal size and type, scaled so `peak` maps to 1; CV_64FC<channels>.
// Throws mirage::Error if the images are empty or differ in size or type.
cv::Mat ssimMap(const cv::Mat& a, const cv::Mat& b, double peak);
// The SSIM map averaged over channels (CV_64F, one channel).
cv::Mat ssimPerPixel(const cv::Mat& a, const cv::Mat& b, double peak);
// Per-pixel squared error summed over channels, in units of peak² (CV_64F, one channel).
cv::Mat squaredErrorPerPixel(const cv::Mat& a, const cv::Mat& b, double peak);

// PSNR (dB) over all pixels, or only where mask != 0 (CV_8U, the images' size). +inf if
// identical, NaN if the mask is empty. Throws mirage::Error on mismatched images or mask.
double psnr(const cv::Mat& a, const cv::Mat& b, double peak, const cv::Mat& mask = cv::Mat());
// Mean SSIM over all channels and pixels (or the masked pixels). NaN if the mask is empty.
double ssim(const cv::Mat& a, const cv::Mat& b, double peak, const cv::Mat& mask = cv::Mat());

// Throws mirage::Error unless a and b are non-empty, of equal size and type, and mask is empty
// or CV_8U of their size.
void checkComparable(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask);

}  // namespace mirage
