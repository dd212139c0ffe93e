// Fuzz target: board files (JSON, tracking/Board.h).
#include <string>

#include "core/Error.h"
#include "tests/fuzz/FuzzTarget.h"
#include "tracking/Board.h"

namespace mirage::fuzz {
namespace {

bool run(const uint8_t* data, size_t size) {
    try {
        const tracking::Board b =
            tracking::Board::parse(std::string(reinterpret_cast<const char*>(data), size), "fuzz");
        (void)b.toJson();
        return true;
    } catch (const Error&) {
        return false;
    }
}

}  // namespace

const Target& target() {
    static const Target t{"board_fuzz",
                          {".json"},
                          {"\"family\":\"tag36h11\"",
                           "\"family\":\"tag25h9\"",
                           "\"family\":\"tagStandard41h12\"",
                           "\"family\":\"\"",
                           "\"id\":",
                           "\"size\":",
                           "\"t\":[0,0,0]",
                           "\"q_wxyz\":[1,0,0,0]",
                           "\"q_wxyz\":[0,0,0,0]",
                           "\"tags\":[]",
                           "\"version\":",
                           "\"units\":",
                           "\"sheet\":{}",
                           "\"width\":",
                           "\"height\":",
                           "1e308",
                           "-1",
                           "NaN",
                           "null",
                           "true",
                           "[]",
                           "{}",
                           ",",
                           ":",
                           "[",
                           "]",
                           "{",
                           "}",
                           "\""},
                          run};
    return t;
}

}  // namespace mirage::fuzz
