#pragma once
// What every pass's options struct uses to validate itself: a range check that names the option
// as the user's code spells it ("caustic.mapSize") and the range it must be in.
#include <string>

namespace mirage::render {

// Throws mirage::Error "renderer option NAME must be RANGE, got VALUE".
[[noreturn]] void failOption(const std::string& name, const std::string& range,
                             const std::string& got);

inline void checkOption(bool ok, const std::string& name, const std::string& range, double got) {
    if (!ok) failOption(name, range, std::to_string(got));
}

}  // namespace mirage::render
