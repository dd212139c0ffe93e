#pragma once
// Errors in mirage come in two kinds (as in pbrt):
//  - mirage::Error: bad input or an unavailable resource (a file, a device, a GL context). The
//    message names the file/field, what is wrong, and what the user can do. Thrown at boundaries;
//    the `mirage` command prints it and exits non-zero.
//  - MR_CHECK: an always-on invariant check. Failing it is a bug in mirage, not bad input.
#include <source_location>
#include <stdexcept>
#include <string>

namespace mirage {

class Error : public std::runtime_error {
public:
    explicit Error(const std::string& what) : std::runtime_error(what) {}
};

// Error about a specific file: "<file>: <problem>".
class FileError : public Error {
public:
    FileError(const std::string& file, const std::string& problem)
        : Error(file + ": " + problem), file_(file) {}
    const std::string& file() const { return file_; }

private:
    std::string file_;
};

[[noreturn]] void checkFailed(const char* expr, const std::string& msg, std::source_location where);

}  // namespace mirage

#define MR_CHECK(cond, msg)                                                                \
    do {                                                                                   \
        if (!(cond)) ::mirage::checkFailed(#cond, (msg), std::source_location::current()); \
    } while (0)
