#pragma once
// JPEG decoding that never returns a damaged image. libjpeg (like FFmpeg's MJPEG decoder, which
// OpenCV's video reader uses) conceals damaged entropy-coded data and still returns an image: grey
// blocks, smeared colours, or in FFmpeg's case leftovers of the previous frame. Here every
// libjpeg warning ("Corrupt JPEG data: ...", "Premature end of JPEG file", a bad Huffman code)
// counts as corruption, so a frame either decodes exactly as it was written or not at all.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include <opencv2/core.hpp>

namespace mirage {

// Largest image accepted, in pixels per side: a damaged header must not allocate gigabytes.
inline constexpr int kMaxJpegSide = 16384;

// 8-bit BGR (CV_8UC3; grey JPEGs are expanded); on any error or warning the empty Mat, with
// `problem` (if given) saying what libjpeg found.
cv::Mat decodeJpegStrict(const uint8_t* data, size_t size, std::string* problem = nullptr);

// An image file as 8-bit BGR, refusing what other readers conceal: a JPEG with any libjpeg
// warning (decodeJpegStrict) and a PNG cut short (no IEND chunk at its end: libpng returns the
// rows it got and fills the rest). Other formats through OpenCV. Empty Mat and `problem` set
// if the file cannot be read.
cv::Mat readImageStrict(const std::filesystem::path& path, std::string* problem = nullptr);

}  // namespace mirage
