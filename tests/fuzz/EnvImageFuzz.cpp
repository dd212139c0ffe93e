// Fuzz target: linear images (environment maps, camera images): .pfm, .hdr, .exr through
// core/image/ImageIO.h's readLinearRgb. The format is chosen by the input's magic bytes, as a
// file's extension would choose it.
#include <cstring>
#include <string>

#include "core/Error.h"
#include "core/image/ImageIO.h"
#include "tests/fuzz/FuzzTarget.h"

namespace mirage::fuzz {
namespace {

bool run(const uint8_t* data, size_t size) {
    const char* ext = ".pfm";
    if (size >= 2 && data[0] == '#' && data[1] == '?') ext = ".hdr";
    if (size >= 4 && std::memcmp(data, "\x76\x2f\x31\x01", 4) == 0) ext = ".exr";
    const auto path = writeScratch(std::string("image") + ext, data, size);
    try {
        const cv::Mat img = readLinearRgb(path);
        (void)img.total();
        return true;
    } catch (const Error&) {
        return false;
    }
}

}  // namespace

const Target& target() {
    static const Target t{"env_image_fuzz",
                          {".pfm", ".hdr", ".exr"},
                          {"PF\n",
                           "Pf\n",
                           "-1.0\n",
                           "1.0\n",
                           "0\n",
                           "65536 65536\n",
                           "#?RADIANCE\n",
                           "FORMAT=32-bit_rle_rgbe\n\n",
                           "-Y 4 +X 8\n",
                           "-Y 100000 +X 100000\n",
                           "EXPOSURE=0\n",
                           "nan",
                           "inf",
                           "-0",
                           std::string("\x76\x2f\x31\x01", 4),
                           "channels",
                           "compression",
                           "dataWindow",
                           "displayWindow",
                           "box2i",
                           "chlist"},
                          run};
    return t;
}

}  // namespace mirage::fuzz
