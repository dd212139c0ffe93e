#include "core/scene/GltfScreening.h"

#include <algorithm>

namespace mirage::gltf {
namespace {

uint32_t readLittleEndian32(const std::string& bytes, size_t at) {
    uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(bytes[at + size_t(i)]);
    return v;
}

}  // namespace

const std::set<std::string>& supportedExtensions() {
    static const std::set<std::string> kSupported = {
        "KHR_lights_punctual",         "KHR_materials_emissive_strength",
        "KHR_materials_ior",           "KHR_materials_transmission",
        "KHR_materials_volume",        "KHR_materials_diffuse_transmission",
        "MIRAGE_materials_scattering",
    };
    return kSupported;
}

std::string supportedExtensionList() {
    std::string list;
    for (const std::string& e : supportedExtensions()) list += (list.empty() ? "" : ", ") + e;
    return list;
}

int jsonNestingDepth(const char* text, size_t size) {
    int depth = 0, maxDepth = 0;
    bool inString = false, escaped = false;
    for (size_t i = 0; i < size; ++i) {
        char c = text[i];
        if (inString) {
            if (escaped)
                escaped = false;
            else if (c == '\\')
                escaped = true;
            else if (c == '"')
                inString = false;
            continue;
        }
        if (c == '"')
            inString = true;
        else if (c == '[' || c == '{')
            maxDepth = std::max(maxDepth, ++depth);
        else if (c == ']' || c == '}')
            depth = std::max(0, depth - 1);
    }
    return maxDepth;
}

bool isGlb(const std::string& bytes) {
    return bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0;
}

JsonSpan jsonText(const std::string& bytes) {
    JsonSpan span{0, bytes.size()};
    if (isGlb(bytes) && bytes.size() >= 20) {
        const uint64_t chunkLength = readLittleEndian32(bytes, 12);
        if (20 + chunkLength <= bytes.size()) span = {20, static_cast<size_t>(chunkLength)};
    }
    return span;
}

}  // namespace mirage::gltf
