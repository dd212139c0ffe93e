#pragma once
// Walks the element structure of a Matroska/WebM file (no decoding) to count the video frames
// that are completely on disk and find each frame's bytes. Damaged bytes in the middle (a bad
// element header or size) are skipped up to the next Cluster that parses, and the frames lost
// in between are reported (by their times). Used to check a session's video against frames.csv and
// to detect a file that was cut short (crash, full disk, partial copy). Handles Segments and
// Clusters of unknown size (live/crash-interrupted files) and files written by other muxers
// (ffmpeg).
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

namespace mirage {

// One frame's bytes in the file (a SimpleBlock's or Block's payload after its header).
struct MatroskaBlock {
    uint64_t offset = 0, size = 0;  // bytes of the frame (e.g. one JPEG)
    double seconds = 0;             // block time (cluster time + relative time), seconds
    int position = 0;               // frame number in the video, counting frames lost to damage
    bool laced = false;             // several frames in one block (not written by mirage)
    bool afterGap = false;          // follows damaged bytes that were skipped
    // The cluster's CRC-32 element (mirage writes one per cluster): the checksum and the bytes
    // it covers (the rest of the cluster), when present.
    bool hasCrc = false;
    uint32_t crc = 0;
    uint64_t crcBegin = 0, crcEnd = 0;
    std::string damaged;  // set when the block is known to be damaged
};

// Bytes the scanner could not parse and skipped, resuming at the next Cluster.
struct MatroskaGap {
    uint64_t begin = 0, end = 0;       // byte range skipped
    int firstLost = 0, lastLost = -1;  // frame numbers lost in it (lastLost < firstLost: none
                                       // known; at the end of the file: unknown how many)
    std::string what;                  // what was found broken at `begin`
};

struct MatroskaScan {
    int completeFrames = 0;  // blocks of the video track whose bytes are all in the file
    bool truncated = false;  // the last element runs past the end of the file
    int width = 0, height = 0;
    std::string codecId;                // e.g. "V_MJPEG"
    std::string problem;                // set when the structure is broken (what was found, where)
    std::vector<MatroskaBlock> blocks;  // the video track's frames, in file order
    std::vector<MatroskaGap> gaps;      // damaged stretches skipped (resynchronised)
};

// CRC-32 as Matroska's CRC-32 element uses it (IEEE 802.3, as zlib's crc32).
uint32_t crc32Ieee(const uint8_t* data, size_t size);

// Throws FileError if the file cannot be opened or is not Matroska at all (no EBML header with
// DocType matroska/webm). Damage after the header is reported in the result, not thrown.
MatroskaScan scanMatroska(const std::filesystem::path& path);
// The same on `size` bytes of a seekable stream; `name` is used in error messages.
MatroskaScan scanMatroska(std::istream& in, uint64_t size, const std::string& name);

}  // namespace mirage
