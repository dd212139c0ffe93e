#pragma once
// Range checks for numeric command-line options: CLI11's Range lets NaN through (every
// comparison with NaN is false) and says nothing about infinity. Here a value must parse
// completely as a finite number inside [lo, hi]; the message gives the range.
#include <cmath>
#include <cstdlib>
#include <string>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

namespace mirage::app {

inline CLI::Validator finiteIn(double lo, double hi, bool loOpen = false) {
    const std::string range = fmt::format("{}{}, {}]", loOpen ? "(" : "[", lo, hi);
    return CLI::Validator(
        [lo, hi, loOpen, range](std::string& text) -> std::string {
            const char* begin = text.c_str();
            char* end = nullptr;
            const double v = std::strtod(begin, &end);
            if (end == begin || *end != '\0' || !std::isfinite(v) || v < lo || v > hi ||
                (loOpen && v == lo))
                return "'" + text + "' is not a finite number in " + range;
            return {};
        },
        "in " + range);
}

// Whole numbers in [lo, hi] (also rejects "1.5" and values that overflow an int).
inline CLI::Validator wholeIn(long long lo, long long hi) {
    const std::string range = fmt::format("[{}, {}]", lo, hi);
    return CLI::Validator(
        [lo, hi, range](std::string& text) -> std::string {
            const char* begin = text.c_str();
            char* end = nullptr;
            errno = 0;
            const long long v = std::strtoll(begin, &end, 10);
            if (end == begin || *end != '\0' || errno == ERANGE || v < lo || v > hi)
                return "'" + text + "' is not a whole number in " + range;
            return {};
        },
        "in " + range);
}

}  // namespace mirage::app
