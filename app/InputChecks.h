#pragma once
// Checks of input files a command can make before handing them to a loader, so that a file of
// the wrong kind gets a message that says what it is instead of the loader's complaint about its
// contents (a PNG given as a scene made the JSON parser report "nesting deeper than 64 levels").
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/Error.h"

namespace mirage::app {

// What the first bytes of a file say it is ("a PNG image"), or "" if not recognised.
inline std::string sniffFileKind(const std::string& head) {
    auto starts = [&](const char* magic, size_t n) {
        return head.size() >= n && std::memcmp(head.data(), magic, n) == 0;
    };
    if (starts("\x89PNG", 4)) return "a PNG image";
    if (starts("\xFF\xD8\xFF", 3)) return "a JPEG image";
    if (starts("\x76\x2F\x31\x01", 4)) return "an OpenEXR image";
    if (starts("#?RADIANCE", 10) || starts("#?RGBE", 6)) return "a Radiance HDR image";
    if (starts("PF\n", 3) || starts("Pf\n", 3)) return "a PFM image";
    if (starts("%PDF", 4)) return "a PDF document";
    if (starts("\x1A\x45\xDF\xA3", 4)) return "a Matroska/WebM video";
    if (starts("%YAML", 5)) return "a YAML file";
    return "";
}

// Throws FileError unless `path` looks like a glTF scene: JSON starting with '{' (after
// whitespace or a UTF-8 byte order mark) or binary glTF starting with "glTF".
inline void checkLooksLikeGltf(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return;  // the loader names a missing file itself
    std::string head(64, '\0');
    in.read(head.data(), std::streamsize(head.size()));
    head.resize(size_t(in.gcount()));
    if (head.rfind("glTF", 0) == 0) return;
    size_t i = head.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
    while (i < head.size() && std::strchr(" \t\r\n", head[i])) ++i;
    if (i < head.size() && head[i] == '{') return;
    if (head.empty() && in.eof()) throw FileError(path.string(), "the scene file is empty");
    const std::string kind = sniffFileKind(head);
    throw FileError(path.string(), "not a glTF scene" +
                                       (kind.empty() ? std::string() : " (it is " + kind + ")") +
                                       ": expected glTF JSON (.gltf) or binary glTF (.glb)");
}

}  // namespace mirage::app
