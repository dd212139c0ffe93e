#pragma once
// glTF loading, part 1 of 5: the limits mirage puts on a glTF file and the screening of its bytes
// before tinygltf parses them (SceneLoader.cpp; the other parts: GltfFiles.h, GltfImages.h,
// GltfAccessors.h, GltfReader.h).
#include <cstddef>
#include <cstdint>
#include <set>
#include <string>

namespace mirage::gltf {

// tinygltf takes the size as `unsigned int`; glTF binaries are capped at 4 GiB by the spec anyway.
constexpr uint64_t kMaxFileBytes = 2ull << 30;
// Deeper JSON than this is no glTF anyone writes; refusing it keeps tinygltf's recursive
// conversion of extras/extensions from exhausting the stack on hostile input.
constexpr int kMaxJsonDepth = 64;
// Texture limits: 8192 x 8192 RGBA8 = 256 MiB decoded (a side may reach 16384 if the area fits).
constexpr int kMaxImageSide = 16384;
constexpr uint64_t kMaxImagePixels = 8192ull * 8192ull;
// An accessor without a bufferView (all zeros, maybe with sparse overrides) has no data bounding
// its count; this caps the allocation.
constexpr uint64_t kMaxZeroAccessorCount = 1ull << 24;

// The glTF extensions mirage reads, and the same as a comma-separated list for messages.
const std::set<std::string>& supportedExtensions();
std::string supportedExtensionList();

// Maximum nesting of JSON arrays/objects, skipping string contents.
int jsonNestingDepth(const char* text, size_t size);

// The bytes start with the GLB magic "glTF".
bool isGlb(const std::string& bytes);

// The JSON text of a file: the whole file, or a GLB's first chunk when its header holds.
struct JsonSpan {
    size_t start = 0, size = 0;
};
JsonSpan jsonText(const std::string& bytes);

}  // namespace mirage::gltf
