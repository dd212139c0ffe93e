#pragma once
// Frames of an AVI MJPEG video, read by their byte ranges from the scanner (AviScanner.h) and
// decoded strictly (StrictVideoFrames.h): exactly the image that was written or lost with the
// reason. AVI has no checksum, so a changed coefficient value inside the entropy-coded data (a
// valid JPEG still) cannot be found; every other damage can.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/session/AviScanner.h"
#include "core/session/StrictVideoFrames.h"

namespace mirage {

class AviFrames final : public StrictVideoFrames {
public:
    // Scans the file; throws FileError if it is not AVI (see scanAvi).
    explicit AviFrames(const std::filesystem::path& path);

    // MJPEG video (the stream format's FourCC MJPG); other codecs are FFmpeg's to read.
    bool supported() const override;
    const AviScan& scan() const { return scan_; }
    int count() const override;
    Frame frame(int position) override;
    std::string containerProblem() const override { return scan_.problem; }

private:
    std::filesystem::path path_;
    AviScan scan_;
    std::ifstream in_;
    size_t next_ = 0;  // index into scan_.frames
    std::vector<uint8_t> bytes_;
    StrictJpegFrames jpeg_;
};

}  // namespace mirage
