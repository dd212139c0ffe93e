#include "core/image/LinearImageHeader.h"

#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <set>
#include <string>

#include "core/Error.h"

namespace mirage {

namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
    throw FileError(path.string(), what +
                                       " (damaged file? re-export it as a single-part EXR, "
                                       "a PFM or a Radiance HDR)");
}

void checkSize(const std::filesystem::path& path, int64_t width, int64_t height,
               const std::string& field) {
    if (width <= 0 || height <= 0)
        fail(path, field + " gives an empty image (" + std::to_string(width) + " x " +
                       std::to_string(height) + ")");
    if (width > kMaxLinearImageSide || height > kMaxLinearImageSide ||
        width * height > kMaxLinearImagePixels)
        fail(path, field + " gives " + std::to_string(width) + " x " + std::to_string(height) +
                       " pixels, beyond the limit of " + std::to_string(kMaxLinearImageSide) +
                       " per side and " + std::to_string(kMaxLinearImagePixels) + " in all");
}

// ---- OpenEXR (openexr.com, "OpenEXR File Layout") ----------------------------------------------

constexpr std::array<unsigned char, 4> kExrMagic{0x76, 0x2f, 0x31, 0x01};
constexpr uint32_t kExrTiled = 0x200;
constexpr uint32_t kExrLongNames = 0x400;
constexpr uint32_t kExrDeep = 0x800;
constexpr uint32_t kExrMultipart = 0x1000;
constexpr int kExrMaxCompression = 9;  // NO, RLE, ZIPS, ZIP, PIZ, PXR24, B44, B44A, DWAA, DWAB
constexpr int kExrMaxLineOrder = 2;    // increasing, decreasing, random
constexpr int kExrMaxChannels = 64;

class ExrReader {
public:
    ExrReader(const std::filesystem::path& path, std::string_view bytes)
        : path_(path), bytes_(bytes) {}

    size_t pos() const { return pos_; }
    bool atEnd() const { return pos_ >= bytes_.size(); }

    uint32_t u32(const std::string& field) {
        need(4, field);
        uint32_t v = 0;
        for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(bytes_[pos_ + i]);
        pos_ += 4;
        return v;
    }
    int32_t i32(const std::string& field) { return static_cast<int32_t>(u32(field)); }
    unsigned char u8(const std::string& field) {
        need(1, field);
        return static_cast<unsigned char>(bytes_[pos_++]);
    }
    // A null-terminated string of at most `maxLength` characters (the null not counted), read
    // within [pos, end).
    std::string name(size_t maxLength, size_t end, const std::string& field) {
        const size_t limit = std::min(end, bytes_.size());
        size_t n = 0;
        while (pos_ + n < limit && bytes_[pos_ + n] != '\0') {
            if (n == maxLength)
                fail(path_, field + " is longer than " + std::to_string(maxLength) + " characters");
            ++n;
        }
        if (pos_ + n >= limit) fail(path_, field + " runs past the end of the header");
        std::string s(bytes_.substr(pos_, n));
        pos_ += n + 1;
        return s;
    }
    void skip(size_t n, const std::string& field) {
        need(n, field);
        pos_ += n;
    }
    void seek(size_t p) { pos_ = p; }

private:
    void need(size_t n, const std::string& field) {
        if (bytes_.size() - pos_ < n) fail(path_, field + " runs past the end of the file");
    }

    const std::filesystem::path& path_;
    std::string_view bytes_;
    size_t pos_ = 0;
};

int readChannelList(const std::filesystem::path& path, ExrReader& in, size_t end) {
    std::set<std::string> names;
    while (true) {
        if (in.pos() >= end) fail(path, "EXR 'channels' list has no terminating null");
        const std::string channel = in.name(255, end, "EXR channel name");
        if (channel.empty()) break;
        const std::string field = "EXR channel '" + channel + "'";
        if (!names.insert(channel).second) fail(path, field + " is listed twice");
        if (names.size() > size_t(kExrMaxChannels))
            fail(path,
                 "EXR 'channels' lists more than " + std::to_string(kExrMaxChannels) + " channels");
        const int32_t pixelType = in.i32(field + " pixel type");
        if (pixelType < 0 || pixelType > 2)
            fail(path, field + " has pixel type " + std::to_string(pixelType) +
                           " (0 = uint, 1 = half, 2 = float)");
        in.skip(4, field + " flags");  // pLinear + 3 reserved bytes
        const int32_t xSampling = in.i32(field + " x sampling");
        const int32_t ySampling = in.i32(field + " y sampling");
        if (xSampling != 1 || ySampling != 1)
            fail(path, field + " is subsampled (" + std::to_string(xSampling) + " x " +
                           std::to_string(ySampling) + "); mirage reads full-resolution channels");
        if (in.pos() > end) fail(path, field + " runs past the 'channels' attribute");
    }
    if (in.pos() != end) fail(path, "EXR 'channels' attribute size does not match its list");
    if (names.empty()) fail(path, "EXR 'channels' lists no channel");
    return int(names.size());
}

LinearImageHeader screenExr(const std::filesystem::path& path, std::string_view bytes) {
    ExrReader in(path, bytes);
    in.skip(4, "EXR magic number");
    const uint32_t version = in.u32("EXR version field");
    if ((version & 0xff) != 2)
        fail(path, "EXR version " + std::to_string(version & 0xff) + " (only version 2 exists)");
    if (version & (kExrDeep | kExrMultipart)) fail(path, "deep or multi-part EXR is not supported");
    const size_t maxName = (version & kExrLongNames) ? 255 : 31;

    LinearImageHeader header;
    header.format = LinearImageFormat::Exr;
    std::set<std::string> seen;
    bool haveDataWindow = false;
    while (true) {
        if (in.atEnd()) fail(path, "EXR header has no end (a null byte after the attributes)");
        const std::string name = in.name(maxName, bytes.size(), "EXR attribute name");
        if (name.empty()) break;
        const std::string type =
            in.name(maxName, bytes.size(), "EXR attribute '" + name + "' type");
        const int32_t size = in.i32("EXR attribute '" + name + "' size");
        if (size < 0 || size_t(size) > bytes.size() - in.pos())
            fail(path, "EXR attribute '" + name + "' claims " + std::to_string(size) +
                           " bytes, more than the file holds");
        if (!seen.insert(name).second) fail(path, "EXR attribute '" + name + "' appears twice");
        const size_t start = in.pos();
        const size_t end = start + size_t(size);
        auto expect = [&](const char* wantType, int32_t wantSize) {
            if (type != wantType)
                fail(path, "EXR attribute '" + name + "' has type '" + type + "', expected '" +
                               wantType + "'");
            if (wantSize >= 0 && size != wantSize)
                fail(path, "EXR attribute '" + name + "' has " + std::to_string(size) +
                               " bytes, expected " + std::to_string(wantSize));
        };
        if (name == "channels") {
            expect("chlist", -1);
            header.channels = readChannelList(path, in, end);
        } else if (name == "compression") {
            expect("compression", 1);
            const int c = in.u8("EXR compression");
            if (c > kExrMaxCompression)
                fail(path, "EXR compression " + std::to_string(c) + " is not a known method");
        } else if (name == "lineOrder") {
            expect("lineOrder", 1);
            const int order = in.u8("EXR lineOrder");
            if (order > kExrMaxLineOrder)
                fail(path, "EXR lineOrder " + std::to_string(order) + " is not a known order");
        } else if (name == "dataWindow" || name == "displayWindow") {
            expect("box2i", 16);
            const int64_t xMin = in.i32("EXR " + name);
            const int64_t yMin = in.i32("EXR " + name);
            const int64_t xMax = in.i32("EXR " + name);
            const int64_t yMax = in.i32("EXR " + name);
            checkSize(path, xMax - xMin + 1, yMax - yMin + 1, "EXR " + name);
            if (name == "dataWindow") {
                header.width = xMax - xMin + 1;
                header.height = yMax - yMin + 1;
                haveDataWindow = true;
            }
        } else if (name == "pixelAspectRatio") {
            expect("float", 4);
            const uint32_t raw = in.u32("EXR pixelAspectRatio");
            float ratio = 0;
            std::memcpy(&ratio, &raw, sizeof ratio);
            if (!std::isfinite(ratio) || ratio <= 0)
                fail(path, "EXR pixelAspectRatio is not a positive number");
        } else if (name == "tiles") {
            expect("tiledesc", 9);
            const uint32_t tileWidth = in.u32("EXR tile width");
            const uint32_t tileHeight = in.u32("EXR tile height");
            if (tileWidth == 0 || tileHeight == 0 || tileWidth > kMaxLinearImageSide ||
                tileHeight > kMaxLinearImageSide)
                fail(path, "EXR tile size " + std::to_string(tileWidth) + " x " +
                               std::to_string(tileHeight) + " is out of range");
        }
        in.seek(end);  // other attributes (and any the checks above did not read) are skipped
    }
    for (const char* required : {"channels", "compression", "dataWindow", "displayWindow",
                                 "lineOrder", "pixelAspectRatio"})
        if (!seen.count(required))
            fail(path, std::string("EXR header lacks the required attribute '") + required + "'");
    if ((version & kExrTiled) && !seen.count("tiles"))
        fail(path, "EXR is marked tiled but has no 'tiles' attribute");
    if (!haveDataWindow) fail(path, "EXR header lacks 'dataWindow'");
    return header;
}

// ---- PFM (Portable Float Map) ---------------------------------------------------------------

LinearImageHeader screenPfm(const std::filesystem::path& path, std::string_view bytes) {
    LinearImageHeader header;
    header.format = LinearImageFormat::Pfm;
    header.channels = bytes[1] == 'F' ? 3 : 1;
    size_t pos = 2;
    auto token = [&](const char* field) {
        while (pos < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
        const size_t start = pos;
        while (pos < bytes.size() && pos - start < 64 &&
               !std::isspace(static_cast<unsigned char>(bytes[pos])))
            ++pos;
        if (pos == start || pos >= bytes.size())
            fail(path, std::string("PFM header: ") + field + " is missing");
        return std::string(bytes.substr(start, pos - start));
    };
    auto integer = [&](const char* field) {
        const std::string t = token(field);
        if (t.size() > 9 || t.find_first_not_of("0123456789") != std::string::npos)
            fail(path, std::string("PFM header: ") + field + " '" + t + "' is not a whole number");
        return int64_t(std::stoll(t));
    };
    header.width = integer("width");
    header.height = integer("height");
    const std::string scaleText = token("scale");
    char* parsedEnd = nullptr;
    const double scale = std::strtod(scaleText.c_str(), &parsedEnd);
    if (parsedEnd != scaleText.c_str() + scaleText.size() || !std::isfinite(scale) || scale == 0)
        fail(path, "PFM header: scale '" + scaleText + "' is not a non-zero number");
    checkSize(path, header.width, header.height, "PFM header");
    ++pos;  // the single whitespace character that ends the header
    const uint64_t needed = uint64_t(header.width) * uint64_t(header.height) *
                            uint64_t(header.channels) * sizeof(float);
    if (bytes.size() < pos || bytes.size() - pos < needed)
        fail(path, "PFM holds " + std::to_string(bytes.size() - std::min(bytes.size(), pos)) +
                       " bytes of pixels, its header promises " + std::to_string(needed) +
                       " (truncated file?)");
    return header;
}

// ---- Radiance HDR (RGBE) ---------------------------------------------------------------------

LinearImageHeader screenHdr(const std::filesystem::path& path, std::string_view bytes) {
    LinearImageHeader header;
    header.format = LinearImageFormat::Hdr;
    header.channels = 3;
    // Header lines up to a blank line, then one resolution line such as "-Y 512 +X 1024".
    constexpr size_t kMaxHeader = 64 * 1024;
    size_t pos = 0;
    bool blank = false;
    while (!blank) {
        const size_t eol = bytes.find('\n', pos);
        if (eol == std::string_view::npos || eol > kMaxHeader)
            fail(path, "Radiance HDR header has no end (a blank line) in its first 64 KiB");
        blank = eol == pos;
        pos = eol + 1;
    }
    const size_t eol = bytes.find('\n', pos);
    if (eol == std::string_view::npos || eol - pos > 64)
        fail(path, "Radiance HDR resolution line is missing");
    const std::string line(bytes.substr(pos, eol - pos));
    char sign1 = 0, axis1 = 0, sign2 = 0, axis2 = 0;
    long long n1 = 0, n2 = 0;
    int used = 0;
    if (std::sscanf(line.c_str(), "%c%c %lld %c%c %lld%n", &sign1, &axis1, &n1, &sign2, &axis2, &n2,
                    &used) != 6 ||
        size_t(used) != line.size() || (sign1 != '+' && sign1 != '-') ||
        (sign2 != '+' && sign2 != '-') ||
        !((axis1 == 'Y' && axis2 == 'X') || (axis1 == 'X' && axis2 == 'Y')))
        fail(path, "Radiance HDR resolution line '" + line + "' is not like '-Y 512 +X 1024'");
    header.height = axis1 == 'Y' ? n1 : n2;
    header.width = axis1 == 'Y' ? n2 : n1;
    checkSize(path, header.width, header.height, "Radiance HDR resolution line");
    return header;
}

}  // namespace

std::string encodedImageSizeProblem(std::string_view bytes) {
    auto u8 = [&](size_t i) { return int64_t(static_cast<unsigned char>(bytes[i])); };
    int64_t width = 0, height = 0;
    const char* kind = "";
    if (bytes.size() >= 24 && bytes.substr(0, 8) == std::string_view("\x89PNG\r\n\x1a\n", 8) &&
        bytes.substr(12, 4) == "IHDR") {
        width = (u8(16) << 24) | (u8(17) << 16) | (u8(18) << 8) | u8(19);
        height = (u8(20) << 24) | (u8(21) << 16) | (u8(22) << 8) | u8(23);
        kind = "PNG";
    } else if (bytes.size() >= 4 && u8(0) == 0xFF && u8(1) == 0xD8) {
        // Walk the marker segments to the first start-of-frame (SOF0..SOF15 but DHT, JPG, DAC).
        size_t p = 2;
        while (p + 4 <= bytes.size()) {
            if (u8(p) != 0xFF) return "";
            const int64_t marker = u8(p + 1);
            if (marker == 0xFF) {
                ++p;
                continue;
            }
            if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD8)) {
                p += 2;
                continue;
            }
            const size_t length = size_t((u8(p + 2) << 8) | u8(p + 3));
            if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 &&
                marker != 0xCC) {
                if (p + 9 > bytes.size()) return "";
                height = (u8(p + 5) << 8) | u8(p + 6);
                width = (u8(p + 7) << 8) | u8(p + 8);
                kind = "JPEG";
                break;
            }
            p += 2 + length;
        }
    }
    if (!*kind) return "";
    if (width > kMaxLinearImageSide || height > kMaxLinearImageSide ||
        width * height > kMaxEncodedImagePixels)
        return std::string(kind) + " image of " + std::to_string(width) + " x " +
               std::to_string(height) + " pixels: too large to read; at most " +
               std::to_string(kMaxEncodedImagePixels) + " pixels (e.g. 8192 x 8192) and " +
               std::to_string(kMaxLinearImageSide) + " per side are read (scale it down)";
    return "";
}

LinearImageHeader screenLinearImageHeader(const std::filesystem::path& path,
                                          std::string_view bytes) {
    if (const std::string problem = encodedImageSizeProblem(bytes); !problem.empty())
        throw FileError(path.string(), problem);
    if (bytes.size() >= 4 && std::memcmp(bytes.data(), kExrMagic.data(), 4) == 0)
        return screenExr(path, bytes);
    if (bytes.size() >= 3 && bytes[0] == 'P' && (bytes[1] == 'F' || bytes[1] == 'f') &&
        std::isspace(static_cast<unsigned char>(bytes[2])))
        return screenPfm(path, bytes);
    if (bytes.rfind("#?RADIANCE", 0) == 0 || bytes.rfind("#?RGBE", 0) == 0)
        return screenHdr(path, bytes);
    return {};
}

}  // namespace mirage
