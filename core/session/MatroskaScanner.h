#pragma once
// Walks the element structure of a Matroska/WebM file (no decoding) to count the video frames
// that are completely on disk. Used to check a session's video against frames.csv and to detect
// a file that was cut short (crash, full disk, partial copy). Handles Segments and Clusters of
// unknown size (live/crash-interrupted files) and files written by other muxers (ffmpeg).
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>

namespace mirage {

struct MatroskaScan {
    int completeFrames = 0;  // blocks of the video track whose bytes are all in the file
    bool truncated = false;  // the last element runs past the end of the file
    int width = 0, height = 0;
    std::string codecId;  // e.g. "V_MJPEG"
    std::string problem;  // set when the structure is broken (what was found, where)
};

// Throws FileError if the file cannot be opened or is not Matroska at all (no EBML header with
// DocType matroska/webm). Damage after the header is reported in the result, not thrown.
MatroskaScan scanMatroska(const std::filesystem::path& path);
// The same on `size` bytes of a seekable stream; `name` is used in error messages.
MatroskaScan scanMatroska(std::istream& in, uint64_t size, const std::string& name);

}  // namespace mirage
