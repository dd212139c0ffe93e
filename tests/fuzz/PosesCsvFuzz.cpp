// Fuzz target: the poses CSV of `mirage track` (core/session/PosesCsv.h).
#include <string>

#include "core/Error.h"
#include "core/session/PosesCsv.h"
#include "tests/fuzz/FuzzTarget.h"

namespace mirage::fuzz {
namespace {

bool run(const uint8_t* data, size_t size) {
    try {
        const auto rows =
            parsePosesCsv(std::string(reinterpret_cast<const char*>(data), size), "fuzz");
        for (const auto& [frame, row] : rows)
            if (row.pose && !row.pose->isFinite()) std::abort();  // must have been rejected
        return true;
    } catch (const Error&) {
        return false;
    }
}

}  // namespace

const Target& target() {
    static const Target t{
        "poses_csv_fuzz",
        {".csv"},
        {"frame",      "state", "reason", "tx",       "ty",  "tz",  "qw",   "qx",    "qy",
         "qz",         "ok",    "lost",   "tracking", "nan", "inf", "-inf", "1e308", "-0",
         "2147483648", "-1",    "\"",     "\"a,b\"",  ",",   "\n",  "\r\n", "#"},
        run};
    return t;
}

}  // namespace mirage::fuzz
