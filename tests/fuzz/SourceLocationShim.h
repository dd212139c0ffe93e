#pragma once
// Force-included (-include) into the libFuzzer build only, when the compiler is clang < 15:
// libstdc++ 12 defines std::source_location only if the compiler has __builtin_source_location,
// which clang gained in version 15, while Debian 12's clang (and libFuzzer) is 14. mirage's
// Error.h needs the type, so this provides a minimal one built on the older __builtin_FILE/LINE
// builtins. Never used in normal (gcc) builds.
#include <source_location>

#if !defined(__cpp_lib_source_location)
namespace std {
struct source_location {
    static constexpr source_location current(const char* file = __builtin_FILE(),
                                             const char* function = __builtin_FUNCTION(),
                                             unsigned line = __builtin_LINE()) noexcept {
        source_location l;
        l.file_ = file;
        l.function_ = function;
        l.line_ = line;
        return l;
    }
    constexpr const char* file_name() const noexcept { return file_; }
    constexpr const char* function_name() const noexcept { return function_; }
    constexpr unsigned line() const noexcept { return line_; }
    constexpr unsigned column() const noexcept { return 0; }

private:
    const char* file_ = "";
    const char* function_ = "";
    unsigned line_ = 0;
};
}  // namespace std
#endif
