// Shared by every fuzz target: the scratch folder and libFuzzer's entry points.
#include <unistd.h>

#include <cstdlib>
#include <fstream>

#include "core/Log.h"
#include "tests/fuzz/FuzzTarget.h"

namespace mirage::fuzz {

namespace fs = std::filesystem;

namespace {

// The loaders that read files get every input through a scratch file. On a disk file system each
// rewrite truncates and discards blocks, which took most of the run time (perf: ext4 truncate and
// block discard under open(O_TRUNC)); a RAM-backed folder (/dev/shm on Linux) avoids it.
// MIRAGE_FUZZ_SCRATCH overrides the choice; the system temp folder is the fallback.
fs::path scratchParent() {
    if (const char* chosen = std::getenv("MIRAGE_FUZZ_SCRATCH"); chosen && *chosen) return chosen;
    std::error_code ec;
    const fs::path shm = "/dev/shm";
    if (fs::is_directory(shm, ec) && ::access(shm.c_str(), W_OK) == 0) return shm;
    return fs::temp_directory_path();
}

}  // namespace

const fs::path& scratchDir() {
    // Never destroyed: a handler that std::atexit registers while a function-local static is
    // still being constructed runs after that static's destructor, so the removal below must
    // not read a static path object (it did, and left the folder behind).
    static const fs::path* const dir = [] {
        auto* d = new fs::path(scratchParent() /
                               ("mirage-fuzz-" + target().name + "-" + std::to_string(::getpid())));
        fs::create_directories(*d);
        return d;
    }();
    static const bool cleanupRegistered = [] {
        std::atexit([] {
            std::error_code ec;
            fs::remove_all(*dir, ec);
        });
        return true;
    }();
    (void)cleanupRegistered;
    return *dir;
}

fs::path writeScratch(const std::string& name, const uint8_t* data, size_t size) {
    const fs::path p = scratchDir() / name;
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
    return p;
}

}  // namespace mirage::fuzz

// libFuzzer calls this once before the first input (the standalone driver does the same itself).
extern "C" int LLVMFuzzerInitialize(int*, char***) {
    spdlog::set_level(spdlog::level::err);  // warnings of rejected inputs would flood the output
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    mirage::fuzz::target().runOnce(data, size);
    return 0;
}
