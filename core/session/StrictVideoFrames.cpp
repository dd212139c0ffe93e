#include "core/session/StrictVideoFrames.h"

#include <fstream>

#include "core/Error.h"
#include "core/image/StrictJpeg.h"
#include "core/session/AviFrames.h"
#include "core/session/MatroskaFrames.h"

namespace mirage {

namespace {

enum class Container { Matroska, Avi, Other };

Container containerOf(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path.string(), "cannot open video for reading");
    char b[12] = {};
    in.read(b, 12);
    if (in.gcount() >= 4 && std::string(b, 4) == "\x1A\x45\xDF\xA3") return Container::Matroska;
    if (in.gcount() == 12 && std::string(b, 4) == "RIFF" && std::string(b + 8, 4) == "AVI ")
        return Container::Avi;
    return Container::Other;
}

}  // namespace

std::unique_ptr<StrictVideoFrames> openStrictVideo(const std::filesystem::path& path) {
    std::unique_ptr<StrictVideoFrames> reader;
    switch (containerOf(path)) {
        case Container::Matroska:
            reader = std::make_unique<MatroskaFrames>(path);
            break;
        case Container::Avi:
            reader = std::make_unique<AviFrames>(path);
            break;
        case Container::Other:
            return nullptr;
    }
    if (!reader->supported()) return nullptr;
    return reader;
}

StrictVideoFrames::Frame StrictJpegFrames::decode(int position, std::vector<uint8_t>& bytes) {
    StrictVideoFrames::Frame f;
    const std::string frame = "frame " + std::to_string(position);
    std::string why;
    f.bgr = decodeJpegStrict(bytes.data(), bytes.size(), &why);
    if (f.bgr.empty()) {
        f.problem = frame + " lost: " + why;
    } else if (width_ > 0 && (f.bgr.cols != width_ || f.bgr.rows != height_)) {
        f.problem = frame + " lost: its JPEG is " + std::to_string(f.bgr.cols) + "x" +
                    std::to_string(f.bgr.rows) + " but the video track is " +
                    std::to_string(width_) + "x" + std::to_string(height_);
        f.bgr.release();
    } else if (previousPosition_ >= 0 && bytes == previousBytes_) {
        // A camera with sensor noise never repeats a frame to the byte: a duplicated block or a
        // frozen camera. The image is right but says nothing new.
        f.problem = frame + " repeats frame " + std::to_string(previousPosition_) +
                    " exactly (a frozen or duplicated frame)";
    }
    if (!f.bgr.empty()) {
        previousBytes_.swap(bytes);
        previousPosition_ = position;
    }
    return f;
}

}  // namespace mirage
