#pragma once
// glTF loading, the check before tinygltf parses the JSON (SceneLoader.cpp): every field of the
// glTF 2.0 core schema (and of the extensions mirage reads) that is present has its type, and
// every external buffer and image URI names a file inside the glTF's folder. tinygltf skips a
// property of the wrong type without a word ("translation": ["a", 0, 0] left the node at the
// origin), so the types are checked here, each error naming the field by its JSON path.
#include <string>

namespace mirage::gltf {

// Throws FileError(file, "<json path>: ...") for the first field of a wrong type, an array of the
// wrong length, or an external URI that would leave the glTF's folder (ContainedPath.h; data:
// URIs are fine). Unknown fields and extras are not checked. Text that is not JSON is left to
// tinygltf (whose message says where the syntax breaks).
void checkGltfSchema(const char* json, size_t size, const std::string& file);

}  // namespace mirage::gltf
