#pragma once
// The allowed range of a number a user gives (a command-line option, a field of a file), held
// once where the number is used: the library's own check and the command line's validator and
// help text (app/NumberChecks.h) are made from the same NumberRange, so they cannot disagree.
#include <cmath>
#include <string>

#include <fmt/format.h>

namespace mirage {

struct NumberRange {
    double lo = 0, hi = 0;
    bool loOpen = false, hiOpen = false;  // open ends exclude the bound itself

    // Finite and inside the range (NaN and infinities never are).
    constexpr bool contains(double v) const {
        return v == v && v - v == 0 && (loOpen ? v > lo : v >= lo) && (hiOpen ? v < hi : v <= hi);
    }
    // "[0, 179)", "(0, 1e+06]": the range as the help and the error messages print it.
    std::string text() const {
        return fmt::format("{}{}, {}{}", loOpen ? "(" : "[", lo, hi, hiOpen ? ")" : "]");
    }
};

}  // namespace mirage
