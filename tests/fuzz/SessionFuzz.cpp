// Fuzz target: a session folder's session.json and frames.csv (core/session/Session.h), read
// with a small valid main.mkv beside them, then every camera's frames. The input is the two
// files joined by a line "----frames.csv----".
#include <filesystem>
#include <string>

#include "core/Error.h"
#include "core/session/Session.h"
#include "tests/fuzz/FuzzTarget.h"

namespace mirage::fuzz {
namespace {

namespace fs = std::filesystem;
const std::string kSeparator = "\n----frames.csv----\n";

bool run(const uint8_t* data, size_t size) {
    const std::string input(reinterpret_cast<const char*>(data), size);
    const size_t cut = input.find(kSeparator);
    const std::string json = input.substr(0, cut);
    const std::string csv = cut == std::string::npos ? "" : input.substr(cut + kSeparator.size());
    const fs::path dir = scratchDir() / "session";
    static const bool once = [&] {
        fs::create_directories(dir);
        fs::copy_file(fs::path(MIRAGE_FUZZ_CORPUS_DIR) / "matroska" / "mirage_4frames.mkv",
                      dir / "main.mkv", fs::copy_options::overwrite_existing);
        return true;
    }();
    (void)once;
    writeScratch("session/session.json", reinterpret_cast<const uint8_t*>(json.data()),
                 json.size());
    writeScratch("session/frames.csv", reinterpret_cast<const uint8_t*>(csv.data()), csv.size());
    try {
        SessionReadReport report;
        const Session s = readSession(dir, &report);
        for (const SessionCamera& c : s.cameras) {
            auto frames = openCameraFrames(s, c.name);
            cv::Mat f;
            for (int i = 0; i < 64 && frames->read(f); ++i) {
            }
        }
        return true;
    } catch (const Error&) {
        return false;
    }
}

}  // namespace

const Target& target() {
    static const Target t{"session_fuzz",
                          {".txt"},
                          {"\"format\":\"mirage-session\"",
                           "\"version\":1",
                           "\"version\":2",
                           "\"fps\":",
                           "\"cameras\":[]",
                           "\"video\":\"main.mkv\"",
                           "\"video\":\"../main.mkv\"",
                           "\"video\":\"/dev/zero\"",
                           "\"video\":\"\"",
                           "\"name\":\"main\"",
                           "\"role\":\"environment\"",
                           "\"calibration\":\"\"",
                           "\"frames\":\"frames.csv\"",
                           "\"board\":",
                           "frame,t_main",
                           "t_env",
                           "gt_tx",
                           "gt_qw",
                           "nan",
                           "inf",
                           "1e308",
                           "-1",
                           "2147483648",
                           "null",
                           "[]",
                           "{}",
                           ",",
                           ":",
                           "\n",
                           "\"",
                           "#"},
                          run};
    return t;
}

}  // namespace mirage::fuzz
