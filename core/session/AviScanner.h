#pragma once
// Walks the chunk structure of an AVI (RIFF) file (no decoding) to find each video frame's bytes,
// as MatroskaScanner.h does for Matroska. AVI carries no checksum and no per-frame time: a frame's
// number is its place among the video stream's chunks, so damage must never shift it. The chunk
// walk through the 'movi' list is checked against the index (idx1) where there is one: a chunk
// whose header and index entry disagree is damaged (its frame lost, the others keep their
// numbers); after a chunk header that does not parse the index alone locates the rest. Without
// an index, nothing after damaged bytes can be numbered, and the frames there are reported lost.
// Zero-size video chunks are not frames: AVI writers use them to hold a frame's place in time
// (FFmpeg writes one after each frame when the rate is doubled), and they advance the clock.
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

namespace mirage {

// One video frame's bytes (a chunk's payload, e.g. one JPEG) in the file.
struct AviFrame {
    uint64_t offset = 0, size = 0;  // payload bytes
    double seconds = 0;             // chunk number x the stream's scale / rate
    int position = 0;               // frame number (non-empty video chunks before it)
    std::string damaged;            // set when the chunk is known to be damaged
};

struct AviScan {
    int width = 0, height = 0;  // from the video stream's format (BITMAPINFOHEADER)
    std::string compression;    // the format's FourCC, e.g. "MJPG"
    double secondsPerChunk = 0;
    bool hasIndex = false;   // an idx1 index that matches the file
    bool truncated = false;  // the file ends inside a chunk or list
    int lostAtEnd = 0;       // frames the index puts past the end of the file
    std::string problem;     // what was found broken, and where
    std::vector<AviFrame> frames;
    // First frame number that cannot be known (damage without an index): frames from here on
    // are lost; -1 when every frame is accounted for.
    int unnumberedFrom = -1;
    uint64_t unnumberedAt = 0;  // the byte where the walk stopped
};

// Throws FileError if the file cannot be opened or is not AVI at all (no "RIFF....AVI " header).
// Damage after the header is reported in the result, not thrown.
AviScan scanAvi(const std::filesystem::path& path);
// The same on `size` bytes of a seekable stream; `name` is used in error messages.
AviScan scanAvi(std::istream& in, uint64_t size, const std::string& name);

// True if the file starts like an AVI file ("RIFF" ... "AVI ").
bool looksLikeAvi(const std::filesystem::path& path);

}  // namespace mirage
