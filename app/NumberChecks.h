#pragma once
// The one validator of numeric command-line options. CLI11's Range lets NaN through (every
// comparison with NaN is false), says nothing about infinity, and its unsigned parsing takes
// "-1" as 2^64 - 1. Here a value must parse completely as a finite number inside its range,
// and the same range gives the help's text ("FLOAT:in (0, 179)") and the error message, so
// the two cannot disagree. Ranges that a library checks too come from the library's
// NumberRange constants (core/NumberRange.h), so the command line and the library agree as well.
// Every numeric option of every command uses one of these; the CLI conformance test
// (tests/app/CliConformance_test.cpp) fails on a numeric option without it.
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "core/NumberRange.h"

namespace mirage::app {

// Name of the validators below, which the CLI conformance test looks for.
inline constexpr const char* kNumberCheckName = "number-range";

// Real numbers inside `range` (finite; "1e3" and "0.5" are fine).
inline CLI::Validator finiteIn(const NumberRange& range) {
    const std::string text = range.text();
    return CLI::Validator(
        [range, text](std::string& value) -> std::string {
            const char* begin = value.c_str();
            char* end = nullptr;
            const double v = std::strtod(begin, &end);
            if (end == begin || *end != '\0' || !range.contains(v))
                return "'" + value + "' is not a finite number in " + text;
            return {};
        },
        "in " + text, kNumberCheckName);
}

inline CLI::Validator finiteIn(double lo, double hi, bool loOpen = false) {
    return finiteIn(NumberRange{lo, hi, loOpen, false});
}

// Seeds are unsigned 64-bit, but "-1" must not wrap around to 2^64 - 1: seeds go to 2^63 - 1.
inline constexpr long long kMaxSeed = 0x7fffffffffffffffLL;

// Whole numbers in [lo, hi] (also rejects "1.5", "-0x10" and values that overflow).
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
        "in " + range, kNumberCheckName);
}

}  // namespace mirage::app
