#pragma once
// Image files. In memory, mirage keeps two kinds of images (docs/conventions.md):
//  - camera frames: 8-bit BGR, sRGB-encoded (CV_8UC3), as OpenCV and cameras deliver them;
//  - rendered/radiance images: linear RGB float (CV_32FC3, channel order R, G, B).
// Files: .exr and .pfm hold linear float; .hdr (Radiance) is read as linear; .png/.jpg are
// sRGB-encoded 8-bit (written after exposure scaling and clamping, read back decoded to linear).
#include <filesystem>

#include <opencv2/core.hpp>

namespace mirage {

float srgbToLinear(float encoded);  // IEC 61966-2-1 transfer curve, input/output in [0,1]
float linearToSrgb(float linear);

// Linear RGB float image (CV_32FC3) <-> 8-bit BGR sRGB image (CV_8UC3), `exposure` multiplies
// the linear values first. Values outside [0,1] after exposure are clamped; NaN becomes 0.
cv::Mat linearRgbToSrgbBgr8(const cv::Mat& linearRgb, float exposure = 1.0f);
cv::Mat srgbBgr8ToLinearRgb(const cv::Mat& bgr8);

// Reads any supported file as linear RGB float. Throws FileError if missing or unreadable, or if
// a float image holds NaN or infinity (naming the first such pixel).
cv::Mat readLinearRgb(const std::filesystem::path& path);
// Writes a linear RGB float image; format by extension (.exr, .pfm, .hdr linear; .png, .jpg
// tone-mapped by exposure + sRGB). Written to a temporary name and renamed, so a reader never
// sees a half-written file. Throws FileError on an unknown extension or a failed write.
void writeLinearRgb(const std::filesystem::path& path, const cv::Mat& linearRgb,
                    float exposure = 1.0f);
// Writes an 8-bit BGR image (PNG/JPEG) atomically.
void writeBgr8(const std::filesystem::path& path, const cv::Mat& bgr8);

}  // namespace mirage
