// Fuzz target: Matroska/MJPEG video, the scanner (core/session/MatroskaScanner.h) and the frame
// reader with its strict JPEG decoder (core/session/MatroskaFrames.h). A frame is delivered
// only if it decoded without a warning; otherwise it must say why it is lost.
#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <string>

#include "core/Error.h"
#include "core/session/FrameInventory.h"
#include "core/session/MatroskaFrames.h"
#include "core/session/MatroskaScanner.h"
#include "tests/fuzz/FuzzTarget.h"

namespace mirage::fuzz {
namespace {

bool run(const uint8_t* data, size_t size) {
    try {
        std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
        const MatroskaScan scan = scanMatroska(in, size, "fuzz");
        if (scan.completeFrames < 0) std::abort();
        const auto path = writeScratch("video.mkv", data, size);
        (void)inventoryFrames(path);
        MatroskaFrames frames(path);
        if (!frames.supported()) return true;
        const int n = std::min(frames.count(), 256);
        for (int i = 0; i < n; ++i) {
            const MatroskaFrames::Frame f = frames.frame(i);
            if (f.bgr.empty() && f.problem.empty()) std::abort();  // lost without a reason
        }
        return true;
    } catch (const Error&) {
        return false;
    }
}

}  // namespace

const Target& target() {
    static const Target t{
        "matroska_fuzz",
        {".mkv", ".webm"},
        {std::string("\x1F\x43\xB6\x75", 4),
         std::string("\x1F\x43\xB6\x75\x01\xFF\xFF\xFF\xFF\xFF\xFF\xFF", 12),
         std::string("\xA3\x88\x81\x00\x00\x80", 6), std::string("\xE7\x81\x00", 3),
         std::string("\xFF\xD8", 2), std::string("\xFF\xD9", 2), std::string("\xFF\xDA", 2),
         std::string("\xFF\xC0\x00\x11", 4), std::string("\xFF\xDB\x00\x43", 4),
         std::string("\xFF\xC4", 2), std::string("\xFF\xDD\x00\x04\x00\x01", 6),
         std::string("\xFF\xD0", 2), std::string("\x01\xFF\xFF\xFF\xFF\xFF\xFF\xFF", 8), "V_MJPEG"},
        run};
    return t;
}

}  // namespace mirage::fuzz
