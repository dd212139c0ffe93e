#pragma once
// Files named by other files (a glTF's buffer and image URIs and side files, a session's videos,
// calibrations, board and frame list) are resolved inside the naming file's folder, and only
// there: a reference that is absolute, carries a URI scheme or climbs out of the folder after
// normalisation ("a/../../x") is refused, so that no input can make mirage read a file elsewhere
// on the machine (a scene from the internet naming /etc/passwd or ~/.ssh). One resolver for every
// loader.
#include <filesystem>
#include <string>

namespace mirage {

// Why `reference` (a relative path, '/'-separated) cannot name a file inside its folder: empty,
// absolute, a URI with a scheme ("file:", "http:"), a drive letter, a NUL byte, or leaving the
// folder after normalisation. Empty when it is fine.
std::string containedReferenceProblem(const std::string& reference);

// `folder` / `reference`, normalised, when containedReferenceProblem(reference) is empty; else
// throws FileError(referrer, "<what> '<reference>' <problem>; name a file inside <folder>").
std::filesystem::path resolveContained(const std::filesystem::path& folder,
                                       const std::string& reference, const std::string& referrer,
                                       const std::string& what);

// Whether `path` lies inside `folder` after lexical normalisation of both (no file access).
bool isLexicallyInside(const std::filesystem::path& path, const std::filesystem::path& folder);

// A URI's %XX escapes decoded ("%2e%2e/x" is "../x"); malformed escapes are kept as they are.
std::string percentDecoded(const std::string& uri);

}  // namespace mirage
