#pragma once
// Screens the header of a linear image file (OpenEXR, PFM, Radiance HDR) before the decoder sees
// it. OpenCV hands these files to OpenEXR and its own readers, which trust the header: a damaged
// EXR channel list kept OpenEXR busy for seconds, and a PFM or HDR header may ask for gigabytes
// that the file does not hold. The screen parses only the header, checks it against the format's
// rules and the size limits below, and throws FileError naming the field; a file that passes is
// decoded as before. Files of other formats (PNG, JPEG) pass unchanged.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace mirage {

// Largest accepted width or height (pixels) and pixel count of a linear image: an equirectangular
// environment of 16384 x 8192 is far beyond what the renderer uploads (it resamples to a few
// thousand pixels wide), so anything larger is taken as damage rather than allocated.
inline constexpr int64_t kMaxLinearImageSide = 32768;
inline constexpr int64_t kMaxLinearImagePixels = int64_t(1) << 28;

// Largest PNG or JPEG read (pixels): decoding allocates width x height x channels bytes and the
// linear copy (readLinearRgb) 12 bytes per pixel, so 8192 x 8192 already takes 0.8 GB as linear
// RGB floats. Checked from the header before decoding, so a 16000 x 16000 PNG is refused at once
// with the limit stated instead of failing in the decoder's allocation a minute later.
inline constexpr int64_t kMaxEncodedImagePixels = int64_t(1) << 26;

// What is wrong with a PNG's or JPEG's size as its header states it ("" when it is within
// kMaxLinearImageSide per side and kMaxEncodedImagePixels, or the file is of another format or
// its header cannot be read: the decoder reports that). `bytes` is the start of the file.
std::string encodedImageSizeProblem(std::string_view bytes);

enum class LinearImageFormat { Exr, Pfm, Hdr, Other };

struct LinearImageHeader {
    LinearImageFormat format = LinearImageFormat::Other;
    int64_t width = 0;  // pixels; 0 for Other
    int64_t height = 0;
    int channels = 0;  // channels stored in the file (EXR: channel list entries)
};

// `bytes` is the whole file (PFM's size check needs it). Throws FileError(path, ...) when the
// header breaks the format or the limits (PNG and JPEG: encodedImageSizeProblem).
LinearImageHeader screenLinearImageHeader(const std::filesystem::path& path,
                                          std::string_view bytes);

}  // namespace mirage
