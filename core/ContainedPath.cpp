#include "core/ContainedPath.h"

#include <cctype>

#include "core/Error.h"

namespace mirage {

namespace fs = std::filesystem;

std::string percentDecoded(const std::string& uri) {
    auto hex = [](char c) -> int {
        if (c >= '0' && c <= '9') return c - '0';
        if (c >= 'a' && c <= 'f') return c - 'a' + 10;
        if (c >= 'A' && c <= 'F') return c - 'A' + 10;
        return -1;
    };
    std::string out;
    for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
            out += char(hex(uri[i + 1]) * 16 + hex(uri[i + 2]));
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

std::string containedReferenceProblem(const std::string& reference) {
    if (reference.empty()) return "is empty";
    if (reference.find('\0') != std::string::npos) return "holds a NUL byte";
    if (reference[0] == '/' || reference[0] == '\\' || reference[0] == '~')
        return "is an absolute path";
    // "C:\x", "file:///x", "http://x": a scheme or a drive letter before any '/'.
    const size_t colon = reference.find(':');
    if (colon != std::string::npos && colon < reference.find('/'))
        return "is not a relative path (it starts with '" + reference.substr(0, colon + 1) + "')";
    if (reference.find('\\') != std::string::npos)
        return "uses '\\' (paths inside a folder are written with '/')";
    const fs::path normal = fs::path(reference).lexically_normal();
    if (normal.empty() || *normal.begin() == ".." || normal == ".")
        return "leaves the folder (after normalisation it is '" + normal.string() + "')";
    return {};
}

fs::path resolveContained(const fs::path& folder, const std::string& reference,
                          const std::string& referrer, const std::string& what) {
    const std::string problem = containedReferenceProblem(reference);
    if (!problem.empty())
        throw FileError(referrer,
                        what + " '" + reference + "' " + problem + "; name a file inside " +
                            (folder.empty() ? std::string("its folder") : folder.string()));
    return (folder / fs::path(reference)).lexically_normal();
}

bool isLexicallyInside(const fs::path& path, const fs::path& folder) {
    const fs::path p = path.lexically_normal(), f = folder.lexically_normal();
    const fs::path rel = p.lexically_relative(f);
    return !rel.empty() && *rel.begin() != ".." && rel != ".";
}

}  // namespace mirage
