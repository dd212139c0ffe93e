#pragma once
// Validators of output-path options, so that an output that can never be written (a character
// device such as /dev/full, a socket, a folder where a file is meant, a FIFO where a folder is
// meant) is refused while the command line is parsed, with the same message the command's
// OutputFile would give (core/OutputFile.h: outputTarget). The command still goes through
// OutputFile/checkOutput for everything else (inputs, --force, parent folders).
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include "core/Error.h"
#include "core/OutputFile.h"

namespace mirage::app {

// Name of the validators below, which the CLI conformance test looks for.
inline constexpr const char* kOutputPathCheckName = "output-path";

enum class OutputShape {
    File,          // a file (or a FIFO / standard output written through)
    Folder,        // a folder (or a new path)
    FileOrFolder,  // decided later by the name (OUT.mkv or a folder of PNG frames)
};

inline CLI::Validator outputPath(OutputShape shape) {
    return CLI::Validator(
        [shape](std::string& value) -> std::string {
            if (value.empty()) return "the output path is empty";
            const std::filesystem::path p(value);
            std::error_code ec;
            const bool folder =
                shape == OutputShape::Folder ||
                (shape == OutputShape::FileOrFolder && std::filesystem::is_directory(p, ec));
            try {
                outputTarget(p, "", folder);
            } catch (const Error& e) {
                std::string why = e.what();
                if (why.rfind("mirage: ", 0) == 0) why = why.substr(8);
                return why;
            }
            return {};
        },
        shape == OutputShape::Folder ? "FOLDER" : "FILE", kOutputPathCheckName);
}

}  // namespace mirage::app
