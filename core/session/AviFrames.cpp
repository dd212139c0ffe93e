#include "core/session/AviFrames.h"

#include <cctype>

#include "core/Error.h"

namespace mirage {

AviFrames::AviFrames(const std::filesystem::path& path)
    : path_(path), scan_(scanAvi(path)), in_(path, std::ios::binary) {
    if (!in_) throw FileError(path.string(), "cannot open video for reading");
    jpeg_.setTrackSize(scan_.width, scan_.height);
}

bool AviFrames::supported() const {
    std::string c = scan_.compression;
    for (auto& ch : c) ch = char(std::toupper(static_cast<unsigned char>(ch)));
    return c == "MJPG";
}

int AviFrames::count() const {
    return scan_.frames.empty() ? 0 : scan_.frames.back().position + 1;
}

AviFrames::Frame AviFrames::frame(int position) {
    Frame f;
    const std::string name = "frame " + std::to_string(position);
    while (next_ < scan_.frames.size() && scan_.frames[next_].position < position) ++next_;
    if (next_ >= scan_.frames.size() || scan_.frames[next_].position != position) {
        if (scan_.unnumberedFrom >= 0 && position >= scan_.unnumberedFrom)
            f.problem = name + " lost: the video has damaged bytes at byte " +
                        std::to_string(scan_.unnumberedAt) +
                        " and no index to number the frames after them (" + scan_.problem + ")";
        else
            f.problem = name + " lost: not in the video";
        return f;
    }
    const AviFrame& c = scan_.frames[next_++];
    f.seconds = c.seconds;
    if (!c.damaged.empty()) {
        f.problem = name + " lost: " + c.damaged;
        return f;
    }
    if (c.size > (uint64_t(1) << 30)) {
        f.problem = name + " lost: chunk of " + std::to_string(c.size) + " bytes";
        return f;
    }
    bytes_.resize(size_t(c.size));
    in_.clear();
    in_.seekg(std::streamoff(c.offset));
    in_.read(reinterpret_cast<char*>(bytes_.data()), std::streamsize(c.size));
    if (uint64_t(in_.gcount()) != c.size) {
        f.problem = name + " lost: cannot read its bytes";
        return f;
    }
    f = jpeg_.decode(position, bytes_);
    f.seconds = c.seconds;
    return f;
}

}  // namespace mirage
