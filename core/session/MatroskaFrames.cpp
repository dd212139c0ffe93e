#include "core/session/MatroskaFrames.h"

#include "core/Error.h"

namespace mirage {

MatroskaFrames::MatroskaFrames(const std::filesystem::path& path)
    : path_(path), scan_(scanMatroska(path)), in_(path, std::ios::binary) {
    if (!in_) throw FileError(path.string(), "cannot open video for reading");
    jpeg_.setTrackSize(scan_.width, scan_.height);
}

std::string MatroskaFrames::containerProblem() const {
    return scan_.problem;
}

bool MatroskaFrames::supported() const {
    if (scan_.codecId != "V_MJPEG") return false;
    // A stream of laced blocks is FFmpeg's to read; a lacing flag on a few blocks of an unlaced
    // stream is damage (those frames are lost, see frame()).
    size_t laced = 0;
    for (const MatroskaBlock& b : scan_.blocks) laced += b.laced;
    return laced * 2 <= scan_.blocks.size();
}

int MatroskaFrames::count() const {
    return scan_.blocks.empty() ? 0 : scan_.blocks.back().position + 1;
}

bool MatroskaFrames::clusterChecksumMatches(const MatroskaBlock& b) {
    if (b.crcEnd <= b.crcBegin || b.crcEnd - b.crcBegin > (uint64_t(1) << 30)) return false;
    std::vector<uint8_t> covered(size_t(b.crcEnd - b.crcBegin));
    in_.clear();
    in_.seekg(std::streamoff(b.crcBegin));
    in_.read(reinterpret_cast<char*>(covered.data()), std::streamsize(covered.size()));
    return uint64_t(in_.gcount()) == covered.size() &&
           crc32Ieee(covered.data(), covered.size()) == b.crc;
}

MatroskaFrames::Frame MatroskaFrames::frame(int position) {
    Frame f;
    while (next_ < scan_.blocks.size() && scan_.blocks[next_].position < position) ++next_;
    if (next_ >= scan_.blocks.size() || scan_.blocks[next_].position != position) {
        // No block has this number: it was inside damaged bytes (or past the end).
        f.problem = "frame " + std::to_string(position) + " lost: ";
        for (const MatroskaGap& g : scan_.gaps)
            if (position >= g.firstLost && (position <= g.lastLost || g.lastLost < g.firstLost)) {
                f.problem += "in damaged bytes " + std::to_string(g.begin) + "-" +
                             std::to_string(g.end) + " of the video (" + g.what + ")";
                return f;
            }
        f.problem += "not in the video";
        return f;
    }
    const MatroskaBlock& b = scan_.blocks[next_++];
    f.seconds = b.seconds;
    if (!b.damaged.empty()) {
        f.problem = "frame " + std::to_string(position) + " lost: " + b.damaged;
        return f;
    }
    if (b.laced) {
        f.problem = "frame " + std::to_string(position) +
                    " lost: its block claims lacing in a stream without (damaged block flags)";
        return f;
    }
    if (b.size == 0 || b.size > (uint64_t(1) << 30)) {
        f.problem = "frame " + std::to_string(position) + " lost: block of " +
                    std::to_string(b.size) + " bytes";
        return f;
    }
    bytes_.resize(size_t(b.size));
    in_.clear();
    in_.seekg(std::streamoff(b.offset));
    in_.read(reinterpret_cast<char*>(bytes_.data()), std::streamsize(b.size));
    if (uint64_t(in_.gcount()) != b.size) {
        f.problem = "frame " + std::to_string(position) + " lost: cannot read its bytes";
        return f;
    }
    if (b.hasCrc && !clusterChecksumMatches(b)) {
        f.problem = "frame " + std::to_string(position) +
                    " lost: the checksum of its cluster does not match (damaged bytes)";
        return f;
    }
    const double seconds = f.seconds;
    f = jpeg_.decode(position, bytes_);
    f.seconds = seconds;
    return f;
}

}  // namespace mirage
