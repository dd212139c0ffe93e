#include "core/scene/GltfImages.h"

#include <cstring>
#include <limits>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/scene/GltfScreening.h"

namespace mirage::gltf {
namespace {

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

}  // namespace

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

}  // namespace mirage::gltf
