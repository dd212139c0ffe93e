#pragma once
// Shared helpers for mirage tests: where data lives, where outputs go, image comparison with
// tolerances (never bytes), and running the `mirage` binary for end-to-end tests.
#include <filesystem>
#include <string>

#include <opencv2/core.hpp>

namespace mirage::test {

std::filesystem::path dataDir();      // the project's data/ (MIRAGE_DATA_DIR)
std::filesystem::path testDataDir();  // tests/data/
// A fresh (emptied) folder under the build's test output directory.
std::filesystem::path outputDir(const std::string& name);

// Peak signal-to-noise ratio in dB between two images of equal size and type (any depth);
// `peak` is the signal's maximum (1 for linear float, 255 for 8-bit). Infinity if identical.
double psnr(const cv::Mat& a, const cv::Mat& b, double peak);
// Mean structural similarity (Wang et al. 2004, 11x11 Gaussian window, sigma 1.5) over all
// channels, on images scaled so `peak` maps to 1. Optional mask (CV_8U, nonzero = counted).
double ssim(const cv::Mat& a, const cv::Mat& b, double peak, const cv::Mat& mask = cv::Mat());
// The q-quantile (0..1) of the per-pixel absolute difference (max over channels).
double percentileAbsDiff(const cv::Mat& a, const cv::Mat& b, double q);

struct CommandResult {
    int exitCode = -1;
    std::string output;  // stdout and stderr together
};
// Runs the built `mirage` binary with the given arguments (shell-quoted here).
CommandResult runMirage(const std::vector<std::string>& args);

}  // namespace mirage::test
