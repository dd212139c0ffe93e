#pragma once
// The reference renderer's ground-truth composite of a synthetic session, stored beside the
// footage (`mirage synth --ground-truth-composite`; format in docs/session.md):
//
//   SESSION/ground_truth.json        what is there (format, folders, scene, threshold, render)
//   SESSION/gt_composite/NNNNNN.png  per frame: 8-bit BGR, sRGB-encoded, lossless; what the
//                                    camera would have filmed had the virtual objects been real
//   SESSION/gt_influence/NNNNNN.png  per frame: 8-bit grey; 255 = a virtual object covers the
//                                    pixel, 128 = a real surface the virtual objects change
//                                    (shadow, bounce, reflection) by more than the threshold,
//                                    0 = untouched
//
// NNNNNN is the frame's index in frames.csv (`frame` column). Everything is optional for readers:
// a session without ground_truth.json simply has no ground-truth composite.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

namespace mirage::render {

inline constexpr const char* kGroundTruthFile = "ground_truth.json";
inline constexpr const char* kGroundTruthFormat = "mirage-ground-truth-composite";
inline constexpr int kGroundTruthVersion = 1;

// Influence mask values (CV_8U).
inline constexpr uint8_t kInfluenceNone = 0, kInfluenceChanged = 128, kInfluenceVirtual = 255;

struct GroundTruthInfo {
    std::string compositeFolder = "gt_composite";  // relative to the session folder
    std::string influenceFolder = "gt_influence";
    std::string scene;  // the scene (with its virtual objects) the composite shows, as given to
                        // `mirage synth` (absolute path); a hint for `mirage bench`
    double influenceThreshold = 0.01;  // linear camera units (after exposure), max over channels
    int samplesPerPixel = 0;           // reference renderer passes per frame
    uint64_t seed = 0;
};

// nullopt if the session has no ground_truth.json; FileError if it exists but is invalid
// (unparseable, another format, a newer version, paths leaving the folder).
std::optional<GroundTruthInfo> readGroundTruthInfo(const std::filesystem::path& sessionDir);
void writeGroundTruthInfo(const std::filesystem::path& sessionDir, const GroundTruthInfo& info);

struct GroundTruthFrame {
    cv::Mat compositeSrgb;  // CV_8UC3, BGR, sRGB-encoded
    cv::Mat influence;      // CV_8U, kInfluence* values
};

std::filesystem::path groundTruthCompositePath(const std::filesystem::path& sessionDir,
                                               const GroundTruthInfo& info, int frameIndex);
std::filesystem::path groundTruthInfluencePath(const std::filesystem::path& sessionDir,
                                               const GroundTruthInfo& info, int frameIndex);

// nullopt if either file of the frame is missing; FileError if one is unreadable or the two
// disagree in size.
std::optional<GroundTruthFrame> readGroundTruthFrame(const std::filesystem::path& sessionDir,
                                                     const GroundTruthInfo& info, int frameIndex);
// Writes both files (each atomically: temporary name, then rename).
void writeGroundTruthFrame(const std::filesystem::path& sessionDir, const GroundTruthInfo& info,
                           int frameIndex, const GroundTruthFrame& frame);

// The influence mask from the reference renderer's two images of one frame: L_r (real only) and
// L_rv (real + virtual), linear RGB float (CV_32FC3), and the virtual coverage (CV_32F, [0,1]).
// `gain` brings rendered radiance into camera linear units (the exposure); a pixel is "changed"
// where gain * max over channels |L_rv - L_r|, averaged over the 5x5 pixels around it, exceeds
// `threshold` (the average drops isolated Monte Carlo differences, keeps shadows and bounces).
cv::Mat influenceMask(const cv::Mat& realOnly, const cv::Mat& realAndVirtual,
                      const cv::Mat& virtualCoverage, double gain, double threshold);

}  // namespace mirage::render
