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
#include <string_view>

namespace mirage {

// Largest accepted width or height (pixels) and pixel count of a linear image: an equirectangular
// environment of 16384 x 8192 is far beyond what the renderer uploads (it resamples to a few
// thousand pixels wide), so anything larger is taken as damage rather than allocated.
inline constexpr int64_t kMaxLinearImageSide = 32768;
inline constexpr int64_t kMaxLinearImagePixels = int64_t(1) << 28;

enum class LinearImageFormat { Exr, Pfm, Hdr, Other };

struct LinearImageHeader {
    LinearImageFormat format = LinearImageFormat::Other;
    int64_t width = 0;  // pixels; 0 for Other
    int64_t height = 0;
    int channels = 0;  // channels stored in the file (EXR: channel list entries)
};

// `bytes` is the whole file (PFM's size check needs it). Throws FileError(path, ...) when the
// header breaks the format or the limits.
LinearImageHeader screenLinearImageHeader(const std::filesystem::path& path,
                                          std::string_view bytes);

}  // namespace mirage
