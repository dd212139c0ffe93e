#pragma once
// Durable file writes for crash-safety: data goes to a temporary file beside the target, is
// fsync'ed, then renamed over the target (rename is atomic on POSIX file systems), and the
// folder is fsync'ed so that the rename itself survives a power loss. A reader therefore sees
// either the old file or the complete new one, never a half-written file.
#include <filesystem>
#include <string_view>

namespace mirage {

// Throws mirage::FileError naming `path` when any step fails (the temporary file is removed).
void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes);

// Whole file as bytes; throws mirage::FileError if it cannot be opened or read.
std::string readFileBytes(const std::filesystem::path& path);

}  // namespace mirage
