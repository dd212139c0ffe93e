// glTF 2.0 -> mirage::Scene. tinygltf (Debian's shared build, which already contains the
// TINYGLTF_IMPLEMENTATION) parses the JSON and fetches buffers; everything it leaves unchecked
// (indices, accessor bounds, types, finiteness, the node graph) is validated here before use, so a
// malformed file ends in a FileError naming the object and field, never in a crash.
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include <tiny_gltf.h>
#include <glm/gtc/quaternion.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/Log.h"
#include "core/scene/Scene.h"

namespace mirage {

namespace {

namespace fs = std::filesystem;

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

const std::set<std::string> kSupportedExtensions = {
    "KHR_lights_punctual",  "KHR_materials_emissive_strength",
    "KHR_materials_ior",    "KHR_materials_transmission",
    "KHR_materials_volume",
};

std::string supportedExtensionList() {
    std::string list;
    for (const std::string& e : kSupportedExtensions) list += (list.empty() ? "" : ", ") + e;
    return list;
}

// ---- input screening before tinygltf sees the bytes ----------------------------------------

// Maximum nesting of JSON arrays/objects, skipping string contents.
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

uint32_t readLittleEndian32(const std::string& bytes, size_t at) {
    uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(bytes[at + i]);
    return v;
}

// ---- file access for tinygltf: regular files only, size-capped, no '~' expansion ------------

bool fsFileExists(const std::string& path, void*) {
    std::error_code ec;
    return fs::is_regular_file(path, ec);
}

std::string fsExpandFilePath(const std::string& path, void*) {
    return path;
}

bool fsReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                     void*) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
        if (err) *err += "not a regular file: " + path + "\n";
        return false;
    }
    uintmax_t size = fs::file_size(path, ec);
    if (ec || size > kMaxFileBytes) {
        if (err) *err += "cannot read or too large (> 2 GiB): " + path + "\n";
        return false;
    }
    std::ifstream in(path, std::ios::binary);
    out->resize(static_cast<size_t>(size));
    if (size > 0 &&
        !in.read(reinterpret_cast<char*>(out->data()), static_cast<std::streamsize>(size))) {
        if (err) *err += "read failed: " + path + "\n";
        return false;
    }
    return true;
}

bool fsWriteWholeFile(std::string* err, const std::string&, const std::vector<unsigned char>&,
                      void*) {
    if (err) *err += "mirage's scene loader never writes files\n";
    return false;
}

// ---- images: PNG/JPEG only (what core glTF allows), decoded to RGBA8 ------------------------
// Pixels are decoded by OpenCV (Debian's libpng / libjpeg-turbo, maintained and hardened) rather
// than stb_image. The size is read from the header first so that a hostile header cannot make
// the decoder allocate gigabytes.

uint32_t bigEndian(const unsigned char* p, int bytes) {
    uint32_t v = 0;
    for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
    return v;
}

// Width and height from a PNG IHDR or a JPEG SOFn segment; false if the header is malformed.
bool imageHeaderSize(const unsigned char* bytes, size_t size, bool png, uint32_t& width,
                     uint32_t& height) {
    if (png) {
        if (size < 24 || std::memcmp(bytes + 12, "IHDR", 4) != 0) return false;
        width = bigEndian(bytes + 16, 4);
        height = bigEndian(bytes + 20, 4);
        return true;
    }
    size_t pos = 2;  // after SOI
    while (pos + 4 <= size) {
        if (bytes[pos] != 0xFF) return false;
        const unsigned char marker = bytes[pos + 1];
        if (marker == 0xFF) {  // fill byte
            ++pos;
            continue;
        }
        if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD8)) {  // no length field
            pos += 2;
            continue;
        }
        if (marker == 0xD9 || marker == 0xDA) return false;  // end or scan before any frame
        const size_t length = bigEndian(bytes + pos + 2, 2);
        if (length < 2 || pos + 2 + length > size) return false;
        const bool startOfFrame =
            marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
        if (startOfFrame) {
            if (length < 7) return false;
            height = bigEndian(bytes + pos + 5, 2);
            width = bigEndian(bytes + pos + 7, 2);
            return true;
        }
        pos += 2 + length;
    }
    return false;
}

bool decodeRgba8(const unsigned char* bytes, size_t size, int& width, int& height,
                 std::vector<unsigned char>& pixels, std::string& why) {
    if (size < 8 || size > static_cast<size_t>(std::numeric_limits<int>::max())) {
        why = "its data is " + std::to_string(size) + " bytes (not a PNG or JPEG image)";
        return false;
    }
    static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    static const unsigned char kJpeg[3] = {0xFF, 0xD8, 0xFF};
    const bool png = std::memcmp(bytes, kPng, 8) == 0;
    if (!png && std::memcmp(bytes, kJpeg, 3) != 0) {
        why = "it is neither PNG nor JPEG (the image formats core glTF allows)";
        return false;
    }
    uint32_t w = 0, h = 0;
    if (!imageHeaderSize(bytes, size, png, w, h)) {
        why = std::string("its ") + (png ? "PNG" : "JPEG") + " header is malformed";
        return false;
    }
    auto tooLarge = [&](uint64_t ww, uint64_t hh) {
        return ww == 0 || hh == 0 || ww > kMaxImageSide || hh > kMaxImageSide ||
               ww * hh > kMaxImagePixels;
    };
    if (tooLarge(w, h)) {
        why = "it is " + std::to_string(w) + "x" + std::to_string(h) +
              " pixels; mirage accepts 1x1 up to 8192x8192 (64 Mpixel) textures";
        return false;
    }
    cv::Mat decoded;
    try {
        const cv::Mat encoded(1, static_cast<int>(size), CV_8U, const_cast<unsigned char*>(bytes));
        decoded = cv::imdecode(encoded, cv::IMREAD_UNCHANGED);
    } catch (const cv::Exception&) {
        decoded.release();
    }
    if (decoded.empty() ||
        tooLarge(static_cast<uint64_t>(decoded.cols), static_cast<uint64_t>(decoded.rows))) {
        why = std::string("its ") + (png ? "PNG" : "JPEG") + " data cannot be decoded";
        return false;
    }
    if (decoded.depth() == CV_16U) decoded.convertTo(decoded, CV_8U, 1.0 / 257.0);
    if (decoded.depth() != CV_8U) {
        why = "it decodes to an unsupported pixel depth";
        return false;
    }
    cv::Mat rgba;
    switch (decoded.channels()) {
        case 1:
            cv::cvtColor(decoded, rgba, cv::COLOR_GRAY2RGBA);
            break;
        case 3:
            cv::cvtColor(decoded, rgba, cv::COLOR_BGR2RGBA);
            break;
        case 4:
            cv::cvtColor(decoded, rgba, cv::COLOR_BGRA2RGBA);
            break;
        case 2: {  // grey + alpha
            std::vector<cv::Mat> ga;
            cv::split(decoded, ga);
            cv::merge(std::vector<cv::Mat>{ga[0], ga[0], ga[0], ga[1]}, rgba);
            break;
        }
        default:
            why = "it has " + std::to_string(decoded.channels()) + " channels";
            return false;
    }
    width = rgba.cols;
    height = rgba.rows;
    pixels.resize(static_cast<size_t>(width) * static_cast<size_t>(height) * 4);
    for (int y = 0; y < height; ++y)
        std::memcpy(pixels.data() + static_cast<size_t>(y) * static_cast<size_t>(width) * 4,
                    rgba.ptr(y), static_cast<size_t>(width) * 4);
    return true;
}

// tinygltf's image callback. Images stored in a bufferView are decoded later, after their view
// has been bounds-checked (tinygltf passes a pointer into the buffer without checking the view).
bool loadImageCallback(tinygltf::Image* image, const int index, std::string* err, std::string*, int,
                       int, const unsigned char* bytes, int size, void*) {
    if (image->bufferView >= 0) return true;
    std::string why;
    if (!decodeRgba8(bytes, size > 0 ? static_cast<size_t>(size) : 0, image->width, image->height,
                     image->image, why)) {
        if (err) *err += "image " + std::to_string(index) + ": " + why;
        return false;
    }
    image->component = 4;
    image->bits = 8;
    image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    return true;
}

// ---- small helpers -------------------------------------------------------------------------

const char* typeName(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR:
            return "SCALAR";
        case TINYGLTF_TYPE_VEC2:
            return "VEC2";
        case TINYGLTF_TYPE_VEC3:
            return "VEC3";
        case TINYGLTF_TYPE_VEC4:
            return "VEC4";
        case TINYGLTF_TYPE_MAT2:
            return "MAT2";
        case TINYGLTF_TYPE_MAT3:
            return "MAT3";
        case TINYGLTF_TYPE_MAT4:
            return "MAT4";
        default:
            return "unknown";
    }
}

const char* componentTypeName(int type) {
    switch (type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
            return "BYTE (5120)";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return "UNSIGNED_BYTE (5121)";
        case TINYGLTF_COMPONENT_TYPE_SHORT:
            return "SHORT (5122)";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
            return "UNSIGNED_SHORT (5123)";
        case TINYGLTF_COMPONENT_TYPE_INT:
            return "INT (5124)";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
            return "UNSIGNED_INT (5125)";
        case TINYGLTF_COMPONENT_TYPE_FLOAT:
            return "FLOAT (5126)";
        case TINYGLTF_COMPONENT_TYPE_DOUBLE:
            return "DOUBLE (5130, not glTF)";
        default:
            return "unknown";
    }
}

int componentCount(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR:
            return 1;
        case TINYGLTF_TYPE_VEC2:
            return 2;
        case TINYGLTF_TYPE_VEC3:
            return 3;
        case TINYGLTF_TYPE_VEC4:
            return 4;
        case TINYGLTF_TYPE_MAT2:
            return 4;
        case TINYGLTF_TYPE_MAT3:
            return 9;
        case TINYGLTF_TYPE_MAT4:
            return 16;
        default:
            return 0;
    }
}

int componentBytes(int componentType) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return 1;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
            return 2;
        case TINYGLTF_COMPONENT_TYPE_INT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        case TINYGLTF_COMPONENT_TYPE_FLOAT:
            return 4;
        default:
            return 0;
    }
}

// One component at `p` as a double; normalized integers map to [0,1] or [-1,1] (glTF 3.11).
double readComponent(const unsigned char* p, int componentType, bool normalized) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            int8_t v;
            std::memcpy(&v, p, 1);
            return normalized ? std::max(v / 127.0, -1.0) : v;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
            uint8_t v;
            std::memcpy(&v, p, 1);
            return normalized ? v / 255.0 : v;
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            int16_t v;
            std::memcpy(&v, p, 2);
            return normalized ? std::max(v / 32767.0, -1.0) : v;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t v;
            std::memcpy(&v, p, 2);
            return normalized ? v / 65535.0 : v;
        }
        case TINYGLTF_COMPONENT_TYPE_INT: {
            int32_t v;
            std::memcpy(&v, p, 4);
            return v;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
            uint32_t v;
            std::memcpy(&v, p, 4);
            return v;
        }
        case TINYGLTF_COMPONENT_TYPE_FLOAT: {
            float v;
            std::memcpy(&v, p, 4);
            return v;
        }
        default:
            return 0.0;
    }
}

bool allFinite(const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

bool allFinite(const glm::dmat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

std::string quote(const std::string& s) {
    return "'" + s + "'";
}

// ---- the reader ----------------------------------------------------------------------------

class GltfReader {
public:
    GltfReader(std::string file, fs::path baseDir)
        : file_(std::move(file)), baseDir_(std::move(baseDir)) {}

    Scene read(const std::string& bytes) {
        parse(bytes);
        checkRequiredExtensions();
        scene_.textures.resize(model_.textures.size());
        decodeImages();
        readTextures();
        readMaterials();
        readMeshes();
        readLights();
        readCameras();
        readNodes();
        readEnvironment();
        return std::move(scene_);
    }

private:
    [[noreturn]] void fail(const std::string& problem) const { throw FileError(file_, problem); }

    // A double from the file as a float; values beyond float's range (converting them would be
    // undefined behaviour) and non-finite values are errors naming `what`.
    float toFloat(double v, const std::string& what) const {
        if (!std::isfinite(v) ||
            std::abs(v) > static_cast<double>(std::numeric_limits<float>::max()))
            fail(what + " is " + std::to_string(v) + ", outside the range of a float");
        return static_cast<float>(v);
    }

    void warn(const std::string& message) {
        spdlog::warn("{}: {}", file_, message);
        scene_.warnings.push_back(message);
    }

    // Throws unless 0 <= index < size; `what` names the referring object and field.
    void checkIndex(int index, size_t size, const std::string& what, const char* target) const {
        if (index < 0 || static_cast<size_t>(index) >= size)
            fail(what + " refers to " + target + " " + std::to_string(index) +
                 ", but the file has " + std::to_string(size) + " " + target +
                 (size == 1 ? "" : "s") + " (valid: 0.." +
                 (size == 0 ? std::string("none") : std::to_string(size - 1)) +
                 "); fix the index or add the missing " + target);
    }

    void parse(const std::string& bytes) {
        if (bytes.empty()) fail("the file is empty; expected glTF JSON or a .glb binary");
        if (bytes.size() > kMaxFileBytes)
            fail("the file is larger than 2 GiB; mirage cannot load it");
        const bool binary = isGlb(bytes);
        // The JSON text to screen: the whole file, or the GLB's first chunk when the header holds.
        size_t jsonStart = 0, jsonSize = bytes.size();
        if (binary && bytes.size() >= 20) {
            uint64_t chunkLength = readLittleEndian32(bytes, 12);
            if (20 + chunkLength <= bytes.size()) {
                jsonStart = 20;
                jsonSize = static_cast<size_t>(chunkLength);
            }
        }
        if (jsonNestingDepth(bytes.data() + jsonStart, jsonSize) > kMaxJsonDepth)
            fail("JSON nesting deeper than " + std::to_string(kMaxJsonDepth) +
                 " levels; this is not a glTF file mirage can load (check extras/extensions)");

        tinygltf::TinyGLTF loader;
        loader.SetImageLoader(&loadImageCallback, nullptr);
        loader.SetFsCallbacks(tinygltf::FsCallbacks{&fsFileExists, &fsExpandFilePath,
                                                    &fsReadWholeFile, &fsWriteWholeFile, nullptr});
        std::string err, warnings;
        bool ok = false;
        // tinygltf reports most problems through `err`, but a few malformed inputs surface as
        // standard exceptions (e.g. std::out_of_range from an empty data URI): both become a
        // FileError. Exceptions from mirage's own code below are deliberately not caught here.
        try {
            const std::string base = baseDir_.string();
            if (binary)
                ok = loader.LoadBinaryFromMemory(
                    &model_, &err, &warnings, reinterpret_cast<const unsigned char*>(bytes.data()),
                    static_cast<unsigned int>(bytes.size()), base);
            else
                ok = loader.LoadASCIIFromString(&model_, &err, &warnings, bytes.data(),
                                                static_cast<unsigned int>(bytes.size()), base);
        } catch (const std::bad_alloc&) {
            fail("out of memory while parsing the glTF file");
        } catch (const std::exception& e) {
            fail(std::string("the glTF parser rejected the file: ") + e.what());
        }
        std::istringstream warnLines(warnings);
        for (std::string line; std::getline(warnLines, line);)
            if (!line.empty()) warn("glTF parser: " + line);
        if (!ok) {
            while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
            fail(std::string("not a valid glTF ") + (binary ? "binary (.glb)" : "file") + ": " +
                 (err.empty() ? "parse failed" : err) +
                 "; check the file against the glTF 2.0 specification (e.g. with the Khronos "
                 "glTF-Validator)");
        }
    }

    void checkRequiredExtensions() {
        for (const std::string& ext : model_.extensionsRequired)
            if (!kSupportedExtensions.count(ext))
                fail("extensionsRequired lists " + quote(ext) +
                     ", which mirage does not support (supported: " + supportedExtensionList() +
                     "); export the scene without it");
        for (const std::string& ext : model_.extensionsUsed)
            if (!kSupportedExtensions.count(ext))
                warn("extension " + quote(ext) + " is used but not supported; it is ignored");
    }

    // Bytes of bufferView `viewIndex` after checking it lies inside its buffer.
    std::pair<const unsigned char*, size_t> viewBytes(int viewIndex,
                                                      const std::string& what) const {
        checkIndex(viewIndex, model_.bufferViews.size(), what, "bufferView");
        const tinygltf::BufferView& view = model_.bufferViews[static_cast<size_t>(viewIndex)];
        const std::string viewName = "bufferView " + std::to_string(viewIndex);
        checkIndex(view.buffer, model_.buffers.size(), viewName + " field 'buffer'", "buffer");
        const tinygltf::Buffer& buffer = model_.buffers[static_cast<size_t>(view.buffer)];
        const size_t size = buffer.data.size();
        if (view.byteLength == 0)
            fail(viewName + " has byteLength 0; a bufferView must hold at least one byte");
        if (view.byteOffset > size || view.byteLength > size - view.byteOffset)
            fail(viewName + " covers bytes [" + std::to_string(view.byteOffset) + ", " +
                 std::to_string(view.byteOffset + view.byteLength) + ") of buffer " +
                 std::to_string(view.buffer) + ", which has only " + std::to_string(size) +
                 " bytes; fix byteOffset/byteLength or the buffer");
        return {buffer.data.data() + view.byteOffset, view.byteLength};
    }

    // Reads accessor `index` as doubles, count x components, after checking its type, component
    // type, bounds and (with sparse substitution applied) that every value is finite.
    std::vector<double> readAccessor(int index, const std::string& what, int expectedType,
                                     const std::vector<int>& allowedComponentTypes,
                                     bool requireNormalizedInts) const {
        checkIndex(index, model_.accessors.size(), what, "accessor");
        const tinygltf::Accessor& acc = model_.accessors[static_cast<size_t>(index)];
        const std::string name = "accessor " + std::to_string(index) + " (" + what + ")";
        if (acc.type != expectedType)
            fail(name + " has type " + typeName(acc.type) + ", expected " + typeName(expectedType));
        if (std::find(allowedComponentTypes.begin(), allowedComponentTypes.end(),
                      acc.componentType) == allowedComponentTypes.end()) {
            std::string allowed;
            for (int t : allowedComponentTypes)
                allowed += (allowed.empty() ? "" : ", ") + std::string(componentTypeName(t));
            fail(name + " has componentType " + componentTypeName(acc.componentType) +
                 ", expected one of: " + allowed);
        }
        const bool isInteger = acc.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT;
        if (requireNormalizedInts && isInteger && !acc.normalized)
            fail(name + " stores integers without \"normalized\": true; set it or use FLOAT");
        if (acc.count == 0) fail(name + " has count 0");
        const int components = componentCount(acc.type);
        const size_t compBytes = static_cast<size_t>(componentBytes(acc.componentType));
        const size_t elementBytes = compBytes * static_cast<size_t>(components);
        const bool normalized = acc.normalized;

        std::vector<double> values;
        if (acc.bufferView < 0) {
            if (!acc.sparse.isSparse)
                fail(name + " has neither a bufferView nor sparse data; give it a bufferView");
            if (acc.count > kMaxZeroAccessorCount)
                fail(name + " has no bufferView and count " + std::to_string(acc.count) +
                     "; mirage accepts at most " + std::to_string(kMaxZeroAccessorCount) +
                     " elements for such accessors");
            values.assign(acc.count * static_cast<size_t>(components), 0.0);
        } else {
            auto [data, size] = viewBytes(acc.bufferView, name + " field 'bufferView'");
            const size_t declaredStride =
                model_.bufferViews[static_cast<size_t>(acc.bufferView)].byteStride;
            const size_t stride = declaredStride ? declaredStride : elementBytes;
            if (declaredStride != 0 && declaredStride < elementBytes)
                fail("bufferView " + std::to_string(acc.bufferView) + " has byteStride " +
                     std::to_string(declaredStride) + ", smaller than one element of " + name +
                     " (" + std::to_string(elementBytes) + " bytes)");
            // Overflow-safe form of: byteOffset + stride * (count - 1) + elementBytes <= size.
            if (acc.byteOffset > size || elementBytes > size - acc.byteOffset ||
                (acc.count - 1) > (size - acc.byteOffset - elementBytes) / stride)
                fail(name + " reads " + std::to_string(acc.count) + " elements of " +
                     std::to_string(elementBytes) + " bytes (stride " + std::to_string(stride) +
                     ") from byteOffset " + std::to_string(acc.byteOffset) + " of bufferView " +
                     std::to_string(acc.bufferView) + ", which has only " + std::to_string(size) +
                     " bytes; fix count/byteOffset or the bufferView");
            values.resize(acc.count * static_cast<size_t>(components));
            for (size_t i = 0; i < acc.count; ++i) {
                const unsigned char* element = data + acc.byteOffset + i * stride;
                for (int c = 0; c < components; ++c)
                    values[i * static_cast<size_t>(components) + static_cast<size_t>(c)] =
                        readComponent(element + static_cast<size_t>(c) * compBytes,
                                      acc.componentType, normalized);
            }
        }
        if (acc.sparse.isSparse) applySparse(acc, name, components, compBytes, values);
        for (size_t i = 0; i < values.size(); ++i)
            if (!std::isfinite(values[i]))
                fail(name + " element " + std::to_string(i / static_cast<size_t>(components)) +
                     " component " + std::to_string(i % static_cast<size_t>(components)) + " is " +
                     (std::isnan(values[i]) ? "NaN" : "infinite") + "; vertex data must be finite");
        return values;
    }

    void applySparse(const tinygltf::Accessor& acc, const std::string& name, int components,
                     size_t compBytes, std::vector<double>& values) const {
        const auto& sparse = acc.sparse;
        if (sparse.count <= 0 || static_cast<size_t>(sparse.count) > acc.count)
            fail(name + " sparse.count is " + std::to_string(sparse.count) + "; it must be in 1.." +
                 std::to_string(acc.count));
        const size_t n = static_cast<size_t>(sparse.count);
        const int indexType = sparse.indices.componentType;
        if (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            fail(name + " sparse.indices.componentType is " + componentTypeName(indexType) +
                 ", expected UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
        const size_t indexBytes = static_cast<size_t>(componentBytes(indexType));
        auto [indexData, indexSize] =
            viewBytes(sparse.indices.bufferView, name + " sparse.indices.bufferView");
        auto [valueData, valueSize] =
            viewBytes(sparse.values.bufferView, name + " sparse.values.bufferView");
        const size_t elementBytes = compBytes * static_cast<size_t>(components);
        if (sparse.indices.byteOffset < 0 || sparse.values.byteOffset < 0)
            fail(name + " sparse byteOffset is negative");
        const size_t indexOffset = static_cast<size_t>(sparse.indices.byteOffset);
        const size_t valueOffset = static_cast<size_t>(sparse.values.byteOffset);
        if (indexOffset > indexSize || n > (indexSize - indexOffset) / indexBytes)
            fail(name + " sparse.indices need " + std::to_string(n * indexBytes) +
                 " bytes from byteOffset " + std::to_string(indexOffset) + " but bufferView " +
                 std::to_string(sparse.indices.bufferView) + " has " + std::to_string(indexSize));
        if (valueOffset > valueSize || n > (valueSize - valueOffset) / elementBytes)
            fail(name + " sparse.values need " + std::to_string(n * elementBytes) +
                 " bytes from byteOffset " + std::to_string(valueOffset) + " but bufferView " +
                 std::to_string(sparse.values.bufferView) + " has " + std::to_string(valueSize));
        for (size_t i = 0; i < n; ++i) {
            const double target =
                readComponent(indexData + indexOffset + i * indexBytes, indexType, false);
            if (target >= static_cast<double>(acc.count))
                fail(name + " sparse index " + std::to_string(i) + " is " +
                     std::to_string(static_cast<uint64_t>(target)) + ", outside the accessor's " +
                     std::to_string(acc.count) + " elements");
            const size_t t = static_cast<size_t>(target);
            for (int c = 0; c < components; ++c)
                values[t * static_cast<size_t>(components) + static_cast<size_t>(c)] =
                    readComponent(valueData + valueOffset + i * elementBytes +
                                      static_cast<size_t>(c) * compBytes,
                                  acc.componentType, acc.normalized);
        }
    }

    // ---- images and textures ----

    void decodeImages() {
        images_.resize(model_.images.size());
        for (size_t i = 0; i < model_.images.size(); ++i) {
            tinygltf::Image& image = model_.images[i];
            const std::string name =
                "image " + std::to_string(i) +
                (image.name.empty() ? std::string() : " (" + quote(image.name) + ")");
            Texture& decoded = images_[i];
            decoded.name = image.name;
            if (image.bufferView >= 0) {
                auto [data, size] = viewBytes(image.bufferView, name + " field 'bufferView'");
                std::string why;
                if (!decodeRgba8(data, size, decoded.width, decoded.height, decoded.pixels, why))
                    fail(name + " in bufferView " + std::to_string(image.bufferView) +
                         " cannot be used: " + why);
            } else if (!image.image.empty()) {
                decoded.width = image.width;
                decoded.height = image.height;
                decoded.pixels = std::move(image.image);
            } else {
                fail(name + " could not be read from uri " + quote(image.uri) + " (looked in " +
                     baseDir_.string() + "); put the file there or embed the image");
            }
            MR_CHECK(
                decoded.pixels.size() == static_cast<size_t>(decoded.width) * decoded.height * 4,
                "decoded image size mismatch");
        }
    }

    static Texture::Wrap wrapMode(int mode) {
        if (mode == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE) return Texture::Wrap::ClampToEdge;
        if (mode == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT) return Texture::Wrap::MirroredRepeat;
        return Texture::Wrap::Repeat;
    }

    void readTextures() {
        for (size_t i = 0; i < model_.textures.size(); ++i) {
            const tinygltf::Texture& src = model_.textures[i];
            const std::string name = "texture " + std::to_string(i);
            if (src.source < 0)
                fail(name +
                     " has no 'source' image (image sources from extensions such as "
                     "KHR_texture_basisu are not supported); give it a PNG or JPEG source");
            checkIndex(src.source, images_.size(), name + " field 'source'", "image");
            Texture& dst = scene_.textures[i];
            dst = images_[static_cast<size_t>(src.source)];
            if (!src.name.empty()) dst.name = src.name;
            if (src.sampler >= 0) {
                checkIndex(src.sampler, model_.samplers.size(), name + " field 'sampler'",
                           "sampler");
                const tinygltf::Sampler& s = model_.samplers[static_cast<size_t>(src.sampler)];
                dst.wrapS = wrapMode(s.wrapS);
                dst.wrapT = wrapMode(s.wrapT);
                dst.magFilter = s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST
                                    ? Texture::Filter::Nearest
                                    : Texture::Filter::Linear;
                dst.minFilter = (s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST ||
                                 s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST ||
                                 s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR)
                                    ? Texture::Filter::Nearest
                                    : Texture::Filter::Linear;
                dst.mipmaps = !(s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST ||
                                s.minFilter == TINYGLTF_TEXTURE_FILTER_LINEAR);
            }
        }
        images_.clear();
    }

    // ---- materials ----

    double number(const tinygltf::Value& object, const char* key, double fallback,
                  const std::string& what, double lo, double hi) const {
        if (!object.IsObject() || !object.Has(key)) return fallback;
        const tinygltf::Value& v = object.Get(key);
        if (!v.IsNumber()) fail(what + " field '" + key + "' must be a number");
        double x = v.GetNumberAsDouble();
        // Every such field ends up in a float, so the float range bounds it too.
        const double floatMax = static_cast<double>(std::numeric_limits<float>::max());
        if (!std::isfinite(x) || x < lo || x > hi || std::abs(x) > floatMax)
            fail(what + " field '" + key + "' is " + std::to_string(x) + "; it must be in [" +
                 std::to_string(lo) + ", " +
                 (std::isinf(hi) ? std::string("inf") : std::to_string(hi)) + "]");
        return x;
    }

    TextureRef textureRef(int index, int texCoord, const std::string& what, bool srgb,
                          const tinygltf::ExtensionMap* extensions = nullptr) {
        if (index < 0) return {};
        checkIndex(index, scene_.textures.size(), what + " field 'index'", "texture");
        if (texCoord != 0 && texCoord != 1)
            fail(what + " uses TEXCOORD_" + std::to_string(texCoord) +
                 "; mirage supports only TEXCOORD_0 and TEXCOORD_1");
        if (extensions && extensions->count("KHR_texture_transform"))
            warn(what +
                 " uses KHR_texture_transform, which is not supported; the transform is ignored");
        Texture& texture = scene_.textures[static_cast<size_t>(index)];
        auto [it, inserted] = textureUse_.emplace(index, srgb);
        if (!inserted && it->second != srgb) {
            warn("texture " + std::to_string(index) +
                 " is used both as colour (sRGB) and as data (linear); treated as sRGB");
            it->second = true;
        }
        texture.srgb = it->second;
        return {index, texCoord};
    }

    TextureRef extensionTextureRef(const tinygltf::Value& ext, const char* key,
                                   const std::string& what, bool srgb) {
        if (!ext.Has(key)) return {};
        const tinygltf::Value& info = ext.Get(key);
        const std::string field = what + " " + key;
        if (!info.IsObject() || !info.Has("index") || !info.Get("index").IsInt())
            fail(field + " must be an object with an integer 'index'");
        int texCoord = 0;
        if (info.Has("texCoord")) {
            if (!info.Get("texCoord").IsInt()) fail(field + " field 'texCoord' must be an integer");
            texCoord = info.Get("texCoord").GetNumberAsInt();
        }
        return textureRef(info.Get("index").GetNumberAsInt(), texCoord, field, srgb);
    }

    const tinygltf::Value* extension(const tinygltf::ExtensionMap& map, const char* name,
                                     const std::string& what) const {
        auto it = map.find(name);
        if (it == map.end()) return nullptr;
        if (!it->second.IsObject()) fail(what + " extension " + name + " must be a JSON object");
        return &it->second;
    }

    void readMaterials() {
        constexpr double kInf = std::numeric_limits<double>::infinity();
        for (size_t i = 0; i < model_.materials.size(); ++i) {
            const tinygltf::Material& src = model_.materials[i];
            const std::string name = "material " + std::to_string(i);
            Material m;
            m.name = src.name;
            const auto& pbr = src.pbrMetallicRoughness;
            if (!pbr.baseColorFactor.empty()) {
                if (pbr.baseColorFactor.size() != 4 || !allFinite(pbr.baseColorFactor))
                    fail(name + " pbrMetallicRoughness.baseColorFactor must be 4 finite numbers");
                for (int c = 0; c < 4; ++c) {
                    if (pbr.baseColorFactor[static_cast<size_t>(c)] < 0 ||
                        pbr.baseColorFactor[static_cast<size_t>(c)] > 1)
                        fail(name +
                             " pbrMetallicRoughness.baseColorFactor components must be in [0, 1]");
                    m.baseColor[c] =
                        static_cast<float>(pbr.baseColorFactor[static_cast<size_t>(c)]);
                }
            }
            auto unit = [&](double v, const char* field) {
                if (!std::isfinite(v) || v < 0 || v > 1)
                    fail(name + " " + field + " is " + std::to_string(v) +
                         "; it must be in [0, 1]");
                return static_cast<float>(v);
            };
            m.metallic = unit(pbr.metallicFactor, "pbrMetallicRoughness.metallicFactor");
            m.roughness = unit(pbr.roughnessFactor, "pbrMetallicRoughness.roughnessFactor");
            m.baseColorTexture =
                textureRef(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                           name + " baseColorTexture", true, &pbr.baseColorTexture.extensions);
            m.metallicRoughnessTexture = textureRef(pbr.metallicRoughnessTexture.index,
                                                    pbr.metallicRoughnessTexture.texCoord,
                                                    name + " metallicRoughnessTexture", false,
                                                    &pbr.metallicRoughnessTexture.extensions);
            m.normalTexture =
                textureRef(src.normalTexture.index, src.normalTexture.texCoord,
                           name + " normalTexture", false, &src.normalTexture.extensions);
            if (!std::isfinite(src.normalTexture.scale))
                fail(name + " normalTexture.scale must be finite");
            m.normalScale = toFloat(src.normalTexture.scale, name + " normalTexture.scale");
            m.emissiveTexture =
                textureRef(src.emissiveTexture.index, src.emissiveTexture.texCoord,
                           name + " emissiveTexture", true, &src.emissiveTexture.extensions);
            if (src.occlusionTexture.index >= 0)
                checkIndex(src.occlusionTexture.index, scene_.textures.size(),
                           name + " occlusionTexture field 'index'", "texture");
            float emissiveStrength = 1.0f;
            if (const tinygltf::Value* ext =
                    extension(src.extensions, "KHR_materials_emissive_strength", name))
                emissiveStrength =
                    static_cast<float>(number(*ext, "emissiveStrength", 1.0,
                                              name + " KHR_materials_emissive_strength", 0, kInf));
            if (!src.emissiveFactor.empty()) {
                if (src.emissiveFactor.size() != 3 || !allFinite(src.emissiveFactor))
                    fail(name + " emissiveFactor must be 3 finite numbers");
                for (int c = 0; c < 3; ++c)
                    m.emissive[c] =
                        unit(src.emissiveFactor[static_cast<size_t>(c)], "emissiveFactor") *
                        emissiveStrength;
            }
            m.doubleSided = src.doubleSided;
            if (src.alphaMode == "OPAQUE" || src.alphaMode.empty())
                m.alphaMode = Material::AlphaMode::Opaque;
            else if (src.alphaMode == "MASK")
                m.alphaMode = Material::AlphaMode::Mask;
            else if (src.alphaMode == "BLEND")
                m.alphaMode = Material::AlphaMode::Blend;
            else
                fail(name + " alphaMode is " + quote(src.alphaMode) +
                     "; expected OPAQUE, MASK or BLEND");
            if (!std::isfinite(src.alphaCutoff) || src.alphaCutoff < 0)
                fail(name + " alphaCutoff must be a finite number >= 0");
            m.alphaCutoff = toFloat(src.alphaCutoff, name + " alphaCutoff");

            if (const tinygltf::Value* ext =
                    extension(src.extensions, "KHR_materials_transmission", name)) {
                const std::string what = name + " KHR_materials_transmission";
                m.transmission =
                    static_cast<float>(number(*ext, "transmissionFactor", 0.0, what, 0, 1));
                m.transmissionTexture =
                    extensionTextureRef(*ext, "transmissionTexture", what, false);
            }
            if (const tinygltf::Value* ext = extension(src.extensions, "KHR_materials_ior", name)) {
                m.ior = static_cast<float>(
                    number(*ext, "ior", 1.5, name + " KHR_materials_ior", 1.0, 10.0));
            }
            if (const tinygltf::Value* ext =
                    extension(src.extensions, "KHR_materials_volume", name)) {
                const std::string what = name + " KHR_materials_volume";
                m.thickness =
                    static_cast<float>(number(*ext, "thicknessFactor", 0.0, what, 0, kInf));
                m.thicknessTexture = extensionTextureRef(*ext, "thicknessTexture", what, false);
                if (ext->Has("attenuationDistance")) {
                    double d = number(*ext, "attenuationDistance", kInf, what, 0, kInf);
                    if (d <= 0)
                        fail(what +
                             " field 'attenuationDistance' must be > 0 (omit it for no "
                             "attenuation)");
                    m.attenuationDistance = static_cast<float>(d);
                }
                if (ext->Has("attenuationColor")) {
                    const tinygltf::Value& c = ext->Get("attenuationColor");
                    if (!c.IsArray() || c.ArrayLen() != 3)
                        fail(what + " field 'attenuationColor' must be an array of 3 numbers");
                    for (int k = 0; k < 3; ++k) {
                        const tinygltf::Value& v = c.Get(k);
                        if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()) ||
                            v.GetNumberAsDouble() < 0 || v.GetNumberAsDouble() > 1)
                            fail(what + " attenuationColor[" + std::to_string(k) +
                                 "] must be a number in [0, 1]");
                        m.attenuationColor[k] = static_cast<float>(v.GetNumberAsDouble());
                    }
                }
            }
            if (const tinygltf::Value* mirage = mirageExtras(src.extras, name)) {
                m.roughnessVariation = static_cast<float>(
                    number(*mirage, "roughness_variation", 0.0, name + " extras.mirage", 0, kInf));
            }
            scene_.materials.push_back(std::move(m));
        }
    }

    // extras.mirage of an object, or null; throws if present but not an object.
    const tinygltf::Value* mirageExtras(const tinygltf::Value& extras,
                                        const std::string& what) const {
        if (!extras.IsObject() || !extras.Has("mirage")) return nullptr;
        const tinygltf::Value& m = extras.Get("mirage");
        if (!m.IsObject()) fail(what + " extras.mirage must be a JSON object");
        return &m;
    }

    // ---- meshes ----

    void readMeshes() {
        for (size_t i = 0; i < model_.meshes.size(); ++i) {
            const tinygltf::Mesh& src = model_.meshes[i];
            Mesh mesh;
            mesh.name = src.name;
            for (size_t p = 0; p < src.primitives.size(); ++p) {
                const std::string what =
                    "mesh " + std::to_string(i) + " primitive " + std::to_string(p);
                std::optional<Primitive> prim = readPrimitive(src.primitives[p], what);
                if (prim) mesh.primitives.push_back(std::move(*prim));
            }
            scene_.meshes.push_back(std::move(mesh));
        }
    }

    template <int N>
    std::vector<glm::vec<N, float>> toVectors(const std::vector<double>& flat) const {
        std::vector<glm::vec<N, float>> out(flat.size() / N);
        for (size_t i = 0; i < out.size(); ++i)
            for (int c = 0; c < N; ++c)
                out[i][c] = static_cast<float>(flat[i * N + static_cast<size_t>(c)]);
        return out;
    }

    std::optional<Primitive> readPrimitive(const tinygltf::Primitive& src,
                                           const std::string& what) {
        const int mode = src.mode < 0 ? TINYGLTF_MODE_TRIANGLES : src.mode;
        if (mode == TINYGLTF_MODE_POINTS || mode == TINYGLTF_MODE_LINE ||
            mode == TINYGLTF_MODE_LINE_LOOP || mode == TINYGLTF_MODE_LINE_STRIP) {
            warn(what + " has mode " + std::to_string(mode) +
                 " (points or lines); mirage renders triangles only, skipped");
            return std::nullopt;
        }
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
            mode != TINYGLTF_MODE_TRIANGLE_FAN)
            fail(what + " has mode " + std::to_string(mode) + "; glTF modes are 0..6");
        if (!src.targets.empty())
            warn(what + " has morph targets; they are ignored (base shape used)");

        Primitive prim;
        if (src.material >= 0 || src.material < -1)
            checkIndex(src.material, model_.materials.size(), what + " field 'material'",
                       "material");
        prim.material = src.material;

        auto attribute = [&](const char* key) -> int {
            auto it = src.attributes.find(key);
            return it == src.attributes.end() ? -2 : it->second;
        };
        const int position = attribute("POSITION");
        if (position == -2) fail(what + " has no POSITION attribute");
        const std::vector<int> floatOnly = {TINYGLTF_COMPONENT_TYPE_FLOAT};
        prim.positions = toVectors<3>(
            readAccessor(position, what + " POSITION", TINYGLTF_TYPE_VEC3, floatOnly, false));
        const size_t vertexCount = prim.positions.size();
        auto checkCount = [&](size_t count, const char* key) {
            if (count != vertexCount)
                fail(what + " attribute " + key + " has " + std::to_string(count) +
                     " elements but POSITION has " + std::to_string(vertexCount) +
                     "; all attributes of a primitive need the same count");
        };
        if (int a = attribute("NORMAL"); a != -2) {
            prim.normals = toVectors<3>(
                readAccessor(a, what + " NORMAL", TINYGLTF_TYPE_VEC3, floatOnly, false));
            checkCount(prim.normals.size(), "NORMAL");
        }
        if (int a = attribute("TANGENT"); a != -2) {
            prim.tangents = toVectors<4>(
                readAccessor(a, what + " TANGENT", TINYGLTF_TYPE_VEC4, floatOnly, false));
            checkCount(prim.tangents.size(), "TANGENT");
        }
        const std::vector<int> uvTypes = {TINYGLTF_COMPONENT_TYPE_FLOAT,
                                          TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                          TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT};
        if (int a = attribute("TEXCOORD_0"); a != -2) {
            prim.uv0 = toVectors<2>(
                readAccessor(a, what + " TEXCOORD_0", TINYGLTF_TYPE_VEC2, uvTypes, true));
            checkCount(prim.uv0.size(), "TEXCOORD_0");
        }
        if (int a = attribute("TEXCOORD_1"); a != -2) {
            prim.uv1 = toVectors<2>(
                readAccessor(a, what + " TEXCOORD_1", TINYGLTF_TYPE_VEC2, uvTypes, true));
            checkCount(prim.uv1.size(), "TEXCOORD_1");
        }

        // Indices: any unsigned integer type, or none (then 0..n-1).
        std::vector<uint32_t> raw;
        if (src.indices >= 0 || src.indices < -1) {
            const std::vector<double> idx = readAccessor(
                src.indices, what + " indices", TINYGLTF_TYPE_SCALAR,
                {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                 TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
                false);
            raw.resize(idx.size());
            for (size_t k = 0; k < idx.size(); ++k) {
                if (idx[k] >= static_cast<double>(vertexCount))
                    fail(what + " index " + std::to_string(k) + " is " +
                         std::to_string(static_cast<uint64_t>(idx[k])) +
                         " but the primitive has only " + std::to_string(vertexCount) +
                         " vertices");
                raw[k] = static_cast<uint32_t>(idx[k]);
            }
        } else {
            if (vertexCount > std::numeric_limits<uint32_t>::max())
                fail(what + " has too many vertices");
            raw.resize(vertexCount);
            for (size_t k = 0; k < vertexCount; ++k) raw[k] = static_cast<uint32_t>(k);
        }
        prim.indices = toTriangleList(raw, mode, what);
        if (prim.indices.empty()) {
            warn(what + " has no complete triangle; skipped");
            return std::nullopt;
        }
        if (prim.normals.empty())
            generateFlatNormals(prim);
        else
            repairZeroNormals(prim, what);

        if (prim.material >= 0) {
            const Material& m = scene_.materials[static_cast<size_t>(prim.material)];
            for (const TextureRef* t :
                 {&m.baseColorTexture, &m.metallicRoughnessTexture, &m.normalTexture,
                  &m.emissiveTexture, &m.transmissionTexture, &m.thicknessTexture})
                if (t->valid() && (t->texCoord == 0 ? prim.uv0.empty() : prim.uv1.empty()))
                    warn(what + " uses material " + std::to_string(prim.material) +
                         " whose texture reads TEXCOORD_" + std::to_string(t->texCoord) +
                         ", which the primitive lacks");
        }
        return prim;
    }

    std::vector<uint32_t> toTriangleList(const std::vector<uint32_t>& raw, int mode,
                                         const std::string& what) {
        std::vector<uint32_t> tri;
        if (mode == TINYGLTF_MODE_TRIANGLES) {
            if (raw.size() % 3 != 0)
                warn(what + " has " + std::to_string(raw.size()) +
                     " indices, not a multiple of 3; the last " + std::to_string(raw.size() % 3) +
                     " are ignored");
            tri.assign(raw.begin(),
                       raw.begin() + static_cast<std::ptrdiff_t>(raw.size() - raw.size() % 3));
        } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
            for (size_t k = 0; k + 2 < raw.size(); ++k) {
                // Every other triangle flips its winding so all face the same way (glTF 3.7.2.1).
                if (k % 2 == 0)
                    tri.insert(tri.end(), {raw[k], raw[k + 1], raw[k + 2]});
                else
                    tri.insert(tri.end(), {raw[k + 1], raw[k], raw[k + 2]});
            }
        } else {  // fan
            for (size_t k = 1; k + 1 < raw.size(); ++k)
                tri.insert(tri.end(), {raw[0], raw[k], raw[k + 1]});
        }
        return tri;
    }

    static glm::vec3 faceNormal(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
        glm::dvec3 n = glm::cross(glm::dvec3(b) - glm::dvec3(a), glm::dvec3(c) - glm::dvec3(a));
        double len = glm::length(n);
        // A degenerate triangle covers no area; any unit normal will do.
        return len > 0 && std::isfinite(len) ? glm::vec3(n / len) : glm::vec3(0, 1, 0);
    }

    // glTF 3.7.2.1: without normals, clients must use flat normals. Flat shading needs one vertex
    // per triangle corner, so the primitive is un-indexed.
    static void generateFlatNormals(Primitive& prim) {
        Primitive flat;
        flat.material = prim.material;
        const size_t n = prim.indices.size();
        flat.positions.reserve(n);
        flat.normals.reserve(n);
        for (size_t k = 0; k < n; k += 3) {
            glm::vec3 nrm =
                faceNormal(prim.positions[prim.indices[k]], prim.positions[prim.indices[k + 1]],
                           prim.positions[prim.indices[k + 2]]);
            for (size_t j = 0; j < 3; ++j) {
                uint32_t v = prim.indices[k + j];
                flat.positions.push_back(prim.positions[v]);
                flat.normals.push_back(nrm);
                if (!prim.tangents.empty()) flat.tangents.push_back(prim.tangents[v]);
                if (!prim.uv0.empty()) flat.uv0.push_back(prim.uv0[v]);
                if (!prim.uv1.empty()) flat.uv1.push_back(prim.uv1[v]);
                flat.indices.push_back(static_cast<uint32_t>(k + j));
            }
        }
        prim = std::move(flat);
    }

    // Normals of zero length (invalid glTF, but common) would become NaN when normalised; they
    // are replaced by the area-weighted normal of the triangles around the vertex.
    void repairZeroNormals(Primitive& prim, const std::string& what) {
        size_t bad = 0;
        for (glm::vec3& n : prim.normals) {
            float len = glm::length(n);
            if (len < 1e-8f)
                ++bad;
            else
                n /= len;
        }
        if (bad == 0) return;
        std::vector<glm::dvec3> accumulated(prim.positions.size(), glm::dvec3(0.0));
        for (size_t k = 0; k < prim.indices.size(); k += 3) {
            const glm::dvec3 a(prim.positions[prim.indices[k]]),
                b(prim.positions[prim.indices[k + 1]]), c(prim.positions[prim.indices[k + 2]]);
            const glm::dvec3 n = glm::cross(b - a, c - a);
            for (size_t j = 0; j < 3; ++j) accumulated[prim.indices[k + j]] += n;
        }
        for (size_t v = 0; v < prim.normals.size(); ++v) {
            if (glm::length(prim.normals[v]) >= 0.5f) continue;
            double len = glm::length(accumulated[v]);
            prim.normals[v] = len > 0 && std::isfinite(len) ? glm::vec3(accumulated[v] / len)
                                                            : glm::vec3(0, 1, 0);
        }
        warn(what + " has " + std::to_string(bad) +
             " zero-length normals; replaced by geometric normals");
    }

    // ---- lights and cameras ----

    void readLights() {
        constexpr double kHalfPi = 1.5707963267948966;
        for (size_t i = 0; i < model_.lights.size(); ++i) {
            const tinygltf::Light& src = model_.lights[i];
            const std::string name = "KHR_lights_punctual light " + std::to_string(i);
            Light l;
            l.name = src.name;
            if (src.type == "point")
                l.type = Light::Type::Point;
            else if (src.type == "spot")
                l.type = Light::Type::Spot;
            else if (src.type == "directional")
                l.type = Light::Type::Directional;
            else
                fail(name + " has type " + quote(src.type) +
                     "; expected point, spot or directional");
            if (!src.color.empty()) {
                if (src.color.size() != 3 || !allFinite(src.color))
                    fail(name + " color must be 3 finite numbers");
                for (int c = 0; c < 3; ++c) {
                    if (src.color[static_cast<size_t>(c)] < 0)
                        fail(name + " color must not be negative");
                    l.color[c] = toFloat(src.color[static_cast<size_t>(c)], name + " color");
                }
            }
            if (!std::isfinite(src.intensity) || src.intensity < 0)
                fail(name +
                     " intensity must be a finite number >= 0 (candela for point/spot, lux for "
                     "directional)");
            l.intensity = toFloat(src.intensity, name + " intensity");
            if (!std::isfinite(src.range) || src.range < 0)
                fail(name + " range must be a finite number > 0 (omit it for unlimited range)");
            l.range = toFloat(src.range, name + " range");
            if (l.type == Light::Type::Spot) {
                const double inner = src.spot.innerConeAngle, outer = src.spot.outerConeAngle;
                if (!std::isfinite(inner) || !std::isfinite(outer) || inner < 0 ||
                    outer > kHalfPi + 1e-9 || !(inner < outer))
                    fail(name +
                         " spot cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= "
                         "pi/2 (radians); got " +
                         std::to_string(inner) + " and " + std::to_string(outer));
                l.innerConeAngle = static_cast<float>(inner);
                l.outerConeAngle = static_cast<float>(outer);
            }
            scene_.lights.push_back(l);
        }
    }

    void readCameras() {
        for (size_t i = 0; i < model_.cameras.size(); ++i) {
            const tinygltf::Camera& src = model_.cameras[i];
            const std::string name = "camera " + std::to_string(i);
            CameraNodeInfo c;
            c.name = src.name;
            if (src.type == "perspective") {
                const auto& p = src.perspective;
                if (!std::isfinite(p.yfov) || p.yfov <= 0 || p.yfov >= 3.14159)
                    fail(name + " perspective.yfov must be in (0, pi) radians; got " +
                         std::to_string(p.yfov));
                if (!std::isfinite(p.znear) || p.znear <= 0)
                    fail(name + " perspective.znear must be > 0 metres; got " +
                         std::to_string(p.znear));
                if (!std::isfinite(p.aspectRatio) || p.aspectRatio < 0)
                    fail(name + " perspective.aspectRatio must be > 0 (or absent)");
                if (!std::isfinite(p.zfar) || p.zfar < 0 || (p.zfar > 0 && p.zfar <= p.znear))
                    fail(name +
                         " perspective.zfar must be greater than znear (or absent for infinite)");
                c.yfov = toFloat(p.yfov, name + " yfov");
                c.aspectRatio = toFloat(p.aspectRatio, name + " aspectRatio");
                c.znear = toFloat(p.znear, name + " znear");
                c.infiniteFar = p.zfar == 0;
                c.zfar = c.infiniteFar ? toFloat(std::min(std::max(1000.0, p.znear * 1000.0), 1e30),
                                                 name + " znear * 1000")
                                       : toFloat(p.zfar, name + " zfar");
            } else if (src.type == "orthographic") {
                const auto& o = src.orthographic;
                if (!std::isfinite(o.xmag) || !std::isfinite(o.ymag) || o.xmag == 0 || o.ymag == 0)
                    fail(name + " orthographic.xmag and ymag must be finite and non-zero");
                if (!std::isfinite(o.znear) || !std::isfinite(o.zfar) || o.znear < 0 ||
                    o.zfar <= o.znear)
                    fail(name + " orthographic needs 0 <= znear < zfar");
                c.projection = CameraNodeInfo::Projection::Orthographic;
                c.xmag = toFloat(o.xmag, name + " xmag");
                c.ymag = toFloat(o.ymag, name + " ymag");
                c.znear = toFloat(o.znear, name + " znear");
                c.zfar = toFloat(o.zfar, name + " zfar");
            } else {
                fail(name + " has type " + quote(src.type) +
                     "; expected perspective or orthographic");
            }
            scene_.cameras.push_back(c);
        }
    }

    // ---- nodes ----

    glm::dmat4 localMatrix(const tinygltf::Node& src, const std::string& name) {
        if (!src.matrix.empty()) {
            if (src.matrix.size() != 16) fail(name + " matrix must have 16 numbers (column-major)");
            if (!allFinite(src.matrix)) fail(name + " matrix contains NaN or infinity");
            if (!src.translation.empty() || !src.rotation.empty() || !src.scale.empty())
                warn(name + " has both matrix and TRS; the matrix is used");
            glm::dmat4 m;
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) m[c][r] = src.matrix[static_cast<size_t>(c * 4 + r)];
            return m;
        }
        glm::dvec3 t(0.0), s(1.0);
        glm::dquat q(1.0, 0.0, 0.0, 0.0);
        if (!src.translation.empty()) {
            if (src.translation.size() != 3 || !allFinite(src.translation))
                fail(name + " translation must be 3 finite numbers (metres)");
            t = {src.translation[0], src.translation[1], src.translation[2]};
        }
        if (!src.rotation.empty()) {
            if (src.rotation.size() != 4 || !allFinite(src.rotation))
                fail(name + " rotation must be 4 finite numbers (quaternion x, y, z, w)");
            // glTF stores x, y, z, w; glm's constructor takes w first.
            q = glm::dquat(src.rotation[3], src.rotation[0], src.rotation[1], src.rotation[2]);
            const double len = glm::length(q);
            if (!(len > 1e-6) || !std::isfinite(len))
                fail(name + " rotation quaternion has zero length");
            if (std::abs(len - 1.0) > 1e-3)
                warn(name + " rotation quaternion is not unit length; normalised");
            q /= len;
        }
        if (!src.scale.empty()) {
            if (src.scale.size() != 3 || !allFinite(src.scale))
                fail(name + " scale must be 3 finite numbers");
            s = {src.scale[0], src.scale[1], src.scale[2]};
        }
        // glTF: M = T * R * S.
        glm::dmat4 m = glm::mat4_cast(q);
        m[0] *= s.x;
        m[1] *= s.y;
        m[2] *= s.z;
        m[3] = glm::dvec4(t, 1.0);
        return m;
    }

    void readNodes() {
        const size_t count = model_.nodes.size();
        scene_.nodes.resize(count);
        std::vector<std::optional<bool>> explicitReal(count);
        for (size_t i = 0; i < count; ++i) {
            const tinygltf::Node& src = model_.nodes[i];
            const std::string name = "node " + std::to_string(i) +
                                     (src.name.empty() ? "" : " (" + quote(src.name) + ")");
            Node& node = scene_.nodes[i];
            node.name = src.name;
            node.local = localMatrix(src, name);
            if (src.mesh != -1)
                checkIndex(src.mesh, scene_.meshes.size(), name + " field 'mesh'", "mesh");
            node.mesh = src.mesh;
            if (src.camera != -1)
                checkIndex(src.camera, scene_.cameras.size(), name + " field 'camera'", "camera");
            node.camera = src.camera;
            if (src.skin >= 0) warn(name + " has a skin; skinning is ignored (bind pose used)");
            if (const tinygltf::Value* ext =
                    extension(src.extensions, "KHR_lights_punctual", name)) {
                if (!ext->Has("light") || !ext->Get("light").IsInt())
                    fail(name + " extensions.KHR_lights_punctual needs an integer 'light'");
                const int light = ext->Get("light").GetNumberAsInt();
                checkIndex(light, scene_.lights.size(), name + " KHR_lights_punctual field 'light'",
                           "light");
                node.light = light;
            }
            if (const tinygltf::Value* mirage = mirageExtras(src.extras, name)) {
                if (mirage->Has("real")) {
                    if (!mirage->Get("real").IsBool())
                        fail(name + " extras.mirage.real must be true or false");
                    explicitReal[i] = mirage->Get("real").Get<bool>();
                }
            }
            for (int child : src.children) {
                checkIndex(child, count, name + " field 'children'", "node");
                if (static_cast<size_t>(child) == i)
                    fail(name + " lists itself as a child; the node graph must be a tree");
                Node& c = scene_.nodes[static_cast<size_t>(child)];
                if (c.parent == static_cast<int>(i))
                    fail(name + " lists node " + std::to_string(child) + " twice in 'children'");
                if (c.parent >= 0)
                    fail("node " + std::to_string(child) + " is a child of both node " +
                         std::to_string(c.parent) + " and node " + std::to_string(i) +
                         "; glTF nodes must form disjoint trees");
                c.parent = static_cast<int>(i);
                node.children.push_back(child);
            }
        }

        // World transforms and real/virtual inheritance, top-down from the parentless nodes. Nodes
        // never reached from a parentless node sit on a cycle (every node has at most one parent).
        std::vector<char> visited(count, 0);
        std::vector<int> stack;
        for (size_t i = 0; i < count; ++i)
            if (scene_.nodes[i].parent < 0) stack.push_back(static_cast<int>(i));
        while (!stack.empty()) {
            const size_t i = static_cast<size_t>(stack.back());
            stack.pop_back();
            visited[i] = 1;
            Node& node = scene_.nodes[i];
            const Node* parent =
                node.parent >= 0 ? &scene_.nodes[static_cast<size_t>(node.parent)] : nullptr;
            node.world = parent ? parent->world * node.local : node.local;
            if (!allFinite(node.world))
                fail("node " + std::to_string(i) +
                     " world transform overflows (non-finite); check the scales along its parents");
            const Origin inherited = parent ? parent->origin : Origin::Virtual;
            node.origin =
                explicitReal[i] ? (*explicitReal[i] ? Origin::Real : Origin::Virtual) : inherited;
            if (node.light >= 0 &&
                !(glm::length(glm::dmat3(node.world) * glm::dvec3(0, 0, -1)) > 1e-12))
                fail("node " + std::to_string(i) +
                     " holds a light but its world transform collapses the -Z axis (zero scale)");
            for (int child : node.children) stack.push_back(child);
        }
        for (size_t i = 0; i < count; ++i)
            if (!visited[i])
                fail("node " + std::to_string(i) +
                     " is part of a cycle in the node hierarchy (children lead back to it); "
                     "glTF nodes must form trees");

        // Roots: the default scene (or scene 0); without scenes, every parentless node.
        if (model_.scenes.empty()) {
            if (count > 0) warn("the file has no 'scenes'; all parentless nodes are used as roots");
            for (size_t i = 0; i < count; ++i)
                if (scene_.nodes[i].parent < 0) scene_.roots.push_back(static_cast<int>(i));
            return;
        }
        int sceneIndex = model_.defaultScene;
        if (sceneIndex != -1)
            checkIndex(sceneIndex, model_.scenes.size(), "field 'scene'", "scene");
        else
            sceneIndex = 0;
        sceneIndex_ = sceneIndex;
        std::set<int> seen;
        for (int root : model_.scenes[static_cast<size_t>(sceneIndex)].nodes) {
            const std::string what = "scene " + std::to_string(sceneIndex) + " field 'nodes'";
            checkIndex(root, count, what, "node");
            if (scene_.nodes[static_cast<size_t>(root)].parent >= 0)
                fail(what + " lists node " + std::to_string(root) + ", which is a child of node " +
                     std::to_string(scene_.nodes[static_cast<size_t>(root)].parent) +
                     "; scene roots must be root nodes");
            if (!seen.insert(root).second)
                fail(what + " lists node " + std::to_string(root) + " twice");
            scene_.roots.push_back(root);
        }
    }

    // ---- environment (extras.mirage.environment of the scene in use, else of the asset) ----

    std::string stringField(const tinygltf::Value& object, const char* key, const std::string& what,
                            bool required) const {
        if (!object.Has(key)) {
            if (required) fail(what + " needs a string field '" + key + "'");
            return {};
        }
        if (!object.Get(key).IsString()) fail(what + " field '" + key + "' must be a string");
        return object.Get(key).Get<std::string>();
    }

    fs::path existingFile(const std::string& relative, const std::string& what) const {
        if (relative.empty()) fail(what + " is empty");
        fs::path p = fs::path(relative).is_absolute() ? fs::path(relative) : baseDir_ / relative;
        std::error_code ec;
        p = fs::absolute(p, ec).lexically_normal();
        if (ec || !fs::is_regular_file(p, ec))
            fail(what + " names " + quote(relative) + ", but " + p.string() +
                 " does not exist; paths are relative to the glTF file");
        return p;
    }

    void readEnvironment() {
        const tinygltf::Value* mirage = nullptr;
        std::string where;
        if (sceneIndex_ >= 0) {
            where = "scene " + std::to_string(sceneIndex_);
            mirage = mirageExtras(model_.scenes[static_cast<size_t>(sceneIndex_)].extras, where);
        }
        if (!mirage || !mirage->Has("environment")) {
            where = "asset";
            mirage = mirageExtras(model_.asset.extras, where);
        }
        if (!mirage || !mirage->Has("environment")) return;
        const std::string what = where + " extras.mirage.environment";
        const tinygltf::Value& env = mirage->Get("environment");
        if (!env.IsObject()) fail(what + " must be a JSON object");
        Environment& e = scene_.environment;
        const std::string type = stringField(env, "type", what, true);
        if (type == "none") return;
        constexpr double kInf = std::numeric_limits<double>::infinity();
        e.image = existingFile(stringField(env, "image", what, true), what + " field 'image'");
        e.intensity = static_cast<float>(number(env, "intensity", 1.0, what, 0, kInf));
        if (type == "equirectangular") {
            e.kind = Environment::Kind::Equirectangular;
            e.rotationYDeg = number(env, "rotation_y_deg", 0.0, what, -1e6, 1e6);
        } else if (type == "fisheye") {
            e.kind = Environment::Kind::Fisheye;
            e.calibration = existingFile(stringField(env, "calibration", what, true),
                                         what + " field 'calibration'");
            if (!env.Has("T_world_camera"))
                fail(what + " needs 'T_world_camera': [tx, ty, tz, qw, qx, qy, qz]");
            const tinygltf::Value& t = env.Get("T_world_camera");
            if (!t.IsArray() || t.ArrayLen() != 7)
                fail(what +
                     " field 'T_world_camera' must be 7 numbers [tx, ty, tz, qw, qx, qy, qz]");
            std::array<double, 7> v{};
            for (int k = 0; k < 7; ++k) {
                if (!t.Get(k).IsNumber() || !std::isfinite(t.Get(k).GetNumberAsDouble()))
                    fail(what + " T_world_camera[" + std::to_string(k) +
                         "] must be a finite number");
                v[static_cast<size_t>(k)] = t.Get(k).GetNumberAsDouble();
            }
            glm::dquat q(v[3], v[4], v[5], v[6]);
            const double len = glm::length(q);
            if (!(len > 1e-6)) fail(what + " T_world_camera quaternion has zero length");
            e.T_world_camera.rotation = q / len;
            e.T_world_camera.translation = {v[0], v[1], v[2]};
        } else {
            fail(what + " field 'type' is " + quote(type) +
                 "; expected equirectangular, fisheye or none");
        }
    }

    std::string file_;
    fs::path baseDir_;
    tinygltf::Model model_;
    Scene scene_;
    std::vector<Texture> images_;     // decoded glTF images, before textures copy them
    std::map<int, bool> textureUse_;  // texture index -> used as sRGB colour
    int sceneIndex_ = -1;
};

}  // namespace

Scene loadSceneFromMemory(const std::string& bytes, const std::string& name,
                          const fs::path& baseDir) {
    GltfReader reader(name, baseDir);
    Scene scene = reader.read(bytes);
    scene.source = name;
    return scene;
}

Scene loadScene(const fs::path& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
        throw FileError(path.string(), "no such file (expected a .gltf or .glb scene)");
    const uintmax_t size = fs::file_size(path, ec);
    if (ec || size > kMaxFileBytes)
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
