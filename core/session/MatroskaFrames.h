#pragma once
// Frames of a Matroska MJPEG video (what mirage records), read by their byte ranges from the
// scanner (MatroskaScanner.h) and decoded strictly (core/image/StrictJpeg.h): a frame is either
// exactly the image that was written or reported lost with the reason, never a concealed or
// stale image. When the cluster carries a CRC-32 (mirage writes one per cluster), any damaged
// byte is found, even one that leaves a valid JPEG. Damaged container bytes cost only the frames
// inside them: reading resumes at the next cluster with the frame numbers kept (by the block
// times).
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/session/MatroskaScanner.h"
#include "core/session/StrictVideoFrames.h"

namespace mirage {

class MatroskaFrames final : public StrictVideoFrames {
public:
    // Scans the file; throws FileError if it is not Matroska (see scanMatroska).
    explicit MatroskaFrames(const std::filesystem::path& path);

    // True if this reader decodes the video: V_MJPEG, blocks without lacing (else FFmpeg must).
    bool supported() const override;
    const MatroskaScan& scan() const { return scan_; }
    // Frame numbers 0 .. count()-1 (lost frames included).
    int count() const override;
    // Frame `position` (seconds: its block time); positions must be asked for in increasing
    // order.
    Frame frame(int position) override;
    std::string containerProblem() const override;

private:
    bool clusterChecksumMatches(const MatroskaBlock& b);

    std::filesystem::path path_;
    MatroskaScan scan_;
    std::ifstream in_;
    size_t next_ = 0;  // index into scan_.blocks
    std::vector<uint8_t> bytes_;
    StrictJpegFrames jpeg_;
};

}  // namespace mirage
