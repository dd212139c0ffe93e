// Writes every embedded shader program stage (includes already expanded) under a folder, so that
// glslangValidator can check exactly what the renderer compiles (tests/render/tests.cmake).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "render/Shaders.h"

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s OUTPUT_DIR\n", argv[0]);
        return 2;
    }
    const std::filesystem::path out = argv[1];
    int n = 0;
    for (std::string_view name : mirage::shaders::names()) {
        if (name.ends_with(".glsl")) continue;  // include-only files are checked through users
        const auto path = out / std::string(name);
        std::filesystem::create_directories(path.parent_path());
        std::ofstream f(path, std::ios::binary);
        const std::string_view src = mirage::shaders::source(name);
        f.write(src.data(), std::streamsize(src.size()));
        if (!f) {
            std::fprintf(stderr, "cannot write %s\n", path.string().c_str());
            return 1;
        }
        std::printf("%s\n", std::string(name).c_str());
        ++n;
    }
    return n > 0 ? 0 : 1;
}
