// Shared by every fuzz target: the scratch folder and libFuzzer's entry points.
#include <unistd.h>

#include <cstdlib>
#include <fstream>

#include "core/Log.h"
#include "tests/fuzz/FuzzTarget.h"

namespace mirage::fuzz {

namespace fs = std::filesystem;

const fs::path& scratchDir() {
    static const fs::path dir = [] {
        const fs::path d = fs::temp_directory_path() /
                           ("mirage-fuzz-" + target().name + "-" + std::to_string(::getpid()));
        fs::create_directories(d);
        std::atexit([] {
            std::error_code ec;
            fs::remove_all(scratchDir(), ec);
        });
        return d;
    }();
    return dir;
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
