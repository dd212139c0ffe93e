// Fuzz target for the glTF scene loader (docs/scene.md, "Fuzzing"). The contract under test:
// whatever the bytes, loadSceneFromMemory returns a Scene or throws mirage::Error. Any other
// exception escapes this function and terminates the process, which the fuzzer reports as a crash,
// just like a sanitizer finding or a signal.
//
// Built two ways (tests/fuzz/tests.cmake):
//  - with SceneLoaderFuzzDriver.cpp (any compiler): a time-boxed mutation fuzzer run by ctest;
//  - with clang's libFuzzer (-DMIRAGE_LIBFUZZER=ON): coverage-guided, for long local runs.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/Error.h"
#include "core/Log.h"
#include "core/scene/Scene.h"
#include "tests/fuzz/SceneLoaderFuzz.h"

namespace mirage::fuzz {

bool loadSceneOnce(const uint8_t* data, size_t size) {
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    try {
        // External URIs (mr.png, env.hdr, fisheye.yaml) resolve next to the good seed scenes.
        Scene scene = loadSceneFromMemory(bytes, "fuzz-input", MIRAGE_FUZZ_BASE_DIR);
        // Exercise the helpers too: they walk the node graph the loader validated.
        (void)scene.meshInstances();
        (void)scene.lightInstances();
        (void)scene.hasVirtual();
        for (const MeshInstance& instance : scene.meshInstances())
            for (const Primitive& p :
                 scene.meshes.at(static_cast<size_t>(instance.mesh)).primitives)
                (void)scene.material(p.material);
        return true;
    } catch (const Error&) {
        return false;
    }
}

}  // namespace mirage::fuzz

// libFuzzer calls this once before the first input (the standalone driver does the same itself).
extern "C" int LLVMFuzzerInitialize(int*, char***) {
    spdlog::set_level(spdlog::level::err);  // warnings of rejected inputs would flood the output
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    mirage::fuzz::loadSceneOnce(data, size);
    return 0;
}
