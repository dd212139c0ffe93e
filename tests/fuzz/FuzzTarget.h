#pragma once
// One fuzz target per executable: the loader under test and what the mutation driver
// (FuzzDriver.cpp) needs to know about its format. The contract under test is the same for
// every loader: whatever the bytes, it returns or throws mirage::Error. Any other exception
// escapes runOnce and terminates the process, which the driver reports as a crash, just like a
// sanitizer finding, a signal or an input that runs past the per-input timeout.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace mirage::fuzz {

struct Target {
    std::string name;                         // e.g. "scene_loader_fuzz"
    std::vector<std::string> seedExtensions;  // corpus files used as seeds (empty: all files)
    std::vector<std::string> tokens;          // keys and values of the format the driver inserts
    // true if the input was accepted, false if it was rejected with a mirage::Error.
    bool (*runOnce)(const uint8_t* data, size_t size);
};

// Defined once by each target's source file.
const Target& target();

// A scratch folder for loaders that read files (made once per process, under the system's
// temporary folder; removed at exit).
const std::filesystem::path& scratchDir();
// Writes `size` bytes to scratchDir()/name and returns the path.
std::filesystem::path writeScratch(const std::string& name, const uint8_t* data, size_t size);

}  // namespace mirage::fuzz
