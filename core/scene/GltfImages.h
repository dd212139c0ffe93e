#pragma once
// glTF loading, part 3 of 5: images, PNG/JPEG only (what core glTF allows), decoded to RGBA8
// (SceneLoader.cpp). Pixels are decoded by OpenCV (Debian's libpng / libjpeg-turbo, maintained
// and hardened) rather than stb_image. The size is read from the header first so that a hostile
// header cannot make the decoder allocate gigabytes (limits: GltfScreening.h).
#include <cstddef>
#include <string>
#include <vector>

#include <tiny_gltf.h>

namespace mirage::gltf {

// Decodes a PNG or JPEG to RGBA8 rows (top row first). False with `why` (a phrase continuing
// "the image cannot be used: ...") if it is neither, malformed, or over the size limits.
bool decodeRgba8(const unsigned char* bytes, size_t size, int& width, int& height,
                 std::vector<unsigned char>& pixels, std::string& why);

// tinygltf's image callback (TinyGLTF::SetImageLoader). Images stored in a bufferView are decoded
// later, after their view has been bounds-checked (tinygltf passes a pointer into the buffer
// without checking the view).
bool loadImageCallback(tinygltf::Image* image, const int index, std::string* err, std::string*, int,
                       int, const unsigned char* bytes, int size, void*);

}  // namespace mirage::gltf
