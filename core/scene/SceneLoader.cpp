// glTF 2.0 -> mirage::Scene. tinygltf (Debian's shared build, which already contains the
// TINYGLTF_IMPLEMENTATION) parses the JSON and fetches buffers; everything it leaves unchecked
// (indices, accessor bounds, types, finiteness, the node graph) is validated before use, so a
// malformed file ends in a FileError naming the object and field, never in a crash. The parts:
// GltfScreening.h (limits, screening the bytes), GltfFiles.h (external files, only beside the
// glTF), GltfImages.h (PNG/JPEG decoding), GltfAccessors.h (buffer views and accessors),
// GltfReader.h (the model -> Scene).
#include <fstream>

#include "core/Error.h"
#include "core/scene/GltfReader.h"
#include "core/scene/GltfScreening.h"
#include "core/scene/Scene.h"

namespace mirage {

namespace fs = std::filesystem;

Scene loadSceneFromMemory(const std::string& bytes, const std::string& name,
                          const fs::path& baseDir) {
    Scene scene = gltf::readGltf(bytes, name, baseDir);
    scene.source = name;
    return scene;
}

Scene loadScene(const fs::path& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
        throw FileError(path.string(), "no such file (expected a .gltf or .glb scene)");
    const uintmax_t size = fs::file_size(path, ec);
    if (ec || size > gltf::kMaxFileBytes)
        throw FileError(path.string(), "cannot read the file or it is larger than 2 GiB");
    std::ifstream in(path, std::ios::binary);
    std::string bytes(static_cast<size_t>(size), '\0');
    if (!in.read(bytes.data(), static_cast<std::streamsize>(size)))
        throw FileError(path.string(), "read failed");
    Scene scene = loadSceneFromMemory(bytes, path.string(), fs::absolute(path, ec).parent_path());
    scene.source = fs::absolute(path, ec);
    return scene;
}

}  // namespace mirage
