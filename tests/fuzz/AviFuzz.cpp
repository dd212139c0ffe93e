// Fuzz target: AVI/MJPEG video, the chunk scanner (core/session/AviScanner.h) and the frame reader
// with its strict JPEG decoder (core/session/AviFrames.h), as MatroskaFuzz.cpp does for Matroska.
// A frame is delivered only if it decoded without a warning; otherwise it must say why it is
// lost, and frame numbers only grow.
#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <string>

#include "core/Error.h"
#include "core/session/AviFrames.h"
#include "core/session/AviScanner.h"
#include "core/session/FrameInventory.h"
#include "tests/fuzz/FuzzTarget.h"

namespace mirage::fuzz {
namespace {

bool run(const uint8_t* data, size_t size) {
    try {
        std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
        const AviScan scan = scanAvi(in, size, "fuzz");
        for (size_t i = 1; i < scan.frames.size(); ++i)
            if (scan.frames[i].position <= scan.frames[i - 1].position) std::abort();
        const auto path = writeScratch("video.avi", data, size);
        (void)inventoryFrames(path);
        AviFrames frames(path);
        if (!frames.supported()) return true;
        const int n = std::min(frames.count(), 256);
        for (int i = 0; i < n; ++i) {
            const AviFrames::Frame f = frames.frame(i);
            if (f.bgr.empty() && f.problem.empty()) std::abort();  // lost without a reason
        }
        return true;
    } catch (const Error&) {
        return false;
    }
}

}  // namespace

const Target& target() {
    static const Target t{"avi_fuzz",
                          {".avi"},
                          {"RIFF",
                           "AVI ",
                           "LIST",
                           "hdrl",
                           "avih",
                           "strl",
                           "strh",
                           "strf",
                           "vids",
                           "MJPG",
                           "movi",
                           "00dc",
                           "00db",
                           "01wb",
                           "idx1",
                           "JUNK",
                           "ix00",
                           "rec ",
                           "AVIX",
                           std::string("\x00\x00\x00\x00", 4),
                           std::string("\xFF\xFF\xFF\xFF", 4),
                           std::string("\xFF\xD8", 2),
                           std::string("\xFF\xD9", 2),
                           std::string("\xFF\xDA", 2),
                           std::string("\xFF\xC0\x00\x11", 4),
                           std::string("\xFF\xDB\x00\x43", 4),
                           std::string("\xFF\xC4", 2),
                           std::string("\xFF\xDD\x00\x04\x00\x01", 6)},
                          run};
    return t;
}

}  // namespace mirage::fuzz
