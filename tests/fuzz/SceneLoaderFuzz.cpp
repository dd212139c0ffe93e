// Fuzz target for the glTF scene loader (docs/scene.md, "Fuzzing"). The contract under test:
// whatever the bytes, loadSceneFromMemory returns a Scene or throws mirage::Error. Any other
// exception escapes this function and terminates the process, which the fuzzer reports as a crash,
// just like a sanitizer finding or a signal.
//
// Built two ways (tests/fuzz/tests.cmake):
//  - with FuzzDriver.cpp (any compiler): a time-boxed mutation fuzzer run by ctest;
//  - with clang's libFuzzer (-DMIRAGE_LIBFUZZER=ON): coverage-guided, for long local runs.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/Error.h"
#include "core/Log.h"
#include "core/scene/Scene.h"
#include "tests/fuzz/FuzzTarget.h"
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

namespace mirage::fuzz {

namespace {
const std::vector<std::string> kGltfTokens = {
    "\"bufferView\":",
    "\"byteOffset\":",
    "\"byteLength\":",
    "\"byteStride\":",
    "\"count\":",
    "\"componentType\":",
    "\"type\":\"VEC3\"",
    "\"type\":\"SCALAR\"",
    "\"normalized\":true",
    "\"children\":[0]",
    "\"children\":[1,1]",
    "\"mesh\":0",
    "\"camera\":0",
    "\"mode\":",
    "\"indices\":",
    "\"material\":",
    "\"sparse\":{\"count\":1,\"indices\":{\"bufferView\":0,\"componentType\":5121},\"values\":{"
    "\"bufferView\":0}}",
    "\"extensionsRequired\":[\"EXT_unknown\"]",
    "\"KHR_lights_punctual\":{\"light\":0}",
    "\"KHR_materials_volume\":{\"attenuationDistance\":0}",
    "\"MIRAGE_materials_scattering\":{\"extinction\":5,\"density\":{\"uri\":\"density.nrrd\","
    "\"boundsMin\":[0,0,0],\"boundsMax\":[1,1,1]}}",
    "\"KHR_materials_diffuse_transmission\":{\"diffuseTransmissionFactor\":1}",
    "\"uri\":\"density.raw\",\"dimensions\":[2,2,2],\"type\":\"uint8\"",
    "\"uri\":\"density.nrrd\"",
    "\"extras\":{\"mirage\":{\"real\":true}}",
    "\"extras\":{\"mirage\":{\"environment\":{\"type\":\"fisheye\",\"image\":\"env.hdr\"}}}",
    "\"matrix\":[0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0]",
    "\"rotation\":[0,0,0,0]",
    "\"scale\":[0,0,0]",
    "\"uri\":\"data:application/octet-stream;base64,\"",
    "\"uri\":\"data:image/png;base64,AAAA\"",
    "\"uri\":\"mr.png\"",
    "\"uri\":\"env.hdr\"",
    "\"uri\":\"\"",
    "\"uri\":\".\"",
    "\"source\":0",
    "\"sampler\":0",
    "\"index\":0",
    "\"texCoord\":1",
    "\"scene\":0",
    "\"nodes\":[0]",
    "null",
    "true",
    "false",
    "[]",
    "{}",
    "\"\"",
    ",",
    ":",
    "[",
    "]",
    "{",
    "}",
    "\"",
    "\\u0000",
    "-",
    "."};
}  // namespace

const Target& target() {
    static const Target t{"scene_loader_fuzz", {".gltf", ".glb"}, kGltfTokens, loadSceneOnce};
    return t;
}

}  // namespace mirage::fuzz
