#pragma once
// The kind of a composited output from its name, as `mirage replay` and `mirage live` take it.
#include <cctype>
#include <filesystem>
#include <string>

#include "core/Error.h"

namespace mirage::app {

// OUT.mkv is a video; a name without extension (or an existing folder) is a folder of PNG
// frames; anything else would be a surprise, so it is refused. `command` names the command in
// the message ("mirage replay").
inline bool isVideoOutput(const std::filesystem::path& out, const std::string& command) {
    std::string ext = out.extension().string();
    for (char& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    if (ext == ".mkv") return true;
    if (ext.empty() || std::filesystem::is_directory(out)) return false;
    throw Error(command + ": output '" + out.string() +
                "' must end in .mkv (MJPEG video) or be a folder (no extension) for PNG frames; " +
                ext + " is not written");
}

}  // namespace mirage::app
