#include "core/scene/DensityGrid.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>

#include "core/Error.h"

namespace mirage {
namespace {

size_t sampleBytes(DensitySampleType t) {
    switch (t) {
        case DensitySampleType::Uint8:
            return 1;
        case DensitySampleType::Uint16:
            return 2;
        case DensitySampleType::Float32:
            return 4;
        case DensitySampleType::Float64:
            return 8;
    }
    return 1;
}

void checkDims(int nx, int ny, int nz) {
    for (int n : {nx, ny, nz})
        if (n < 1 || n > kMaxDensityDim)
            throw Error("density grid dimension " + std::to_string(n) + " is outside 1.." +
                        std::to_string(kMaxDensityDim) + "; resample the grid");
    if (size_t(nx) * size_t(ny) * size_t(nz) > kMaxDensitySamples)
        throw Error("density grid of " + std::to_string(nx) + "x" + std::to_string(ny) + "x" +
                    std::to_string(nz) + " samples exceeds the limit of " +
                    std::to_string(kMaxDensitySamples) + " (256^3); resample the grid");
}

// Decodes samples from `data` (exactly count * size bytes) into floats.
DensityGrid decode(const char* data, size_t size, int nx, int ny, int nz, DensitySampleType type,
                   bool bigEndian) {
    checkDims(nx, ny, nz);
    const size_t count = size_t(nx) * size_t(ny) * size_t(nz);
    const size_t bytes = sampleBytes(type);
    if (size != count * bytes)
        throw Error("density grid data has " + std::to_string(size) + " bytes, but " +
                    std::to_string(nx) + "x" + std::to_string(ny) + "x" + std::to_string(nz) +
                    " samples of " + std::to_string(bytes) + " byte(s) need " +
                    std::to_string(count * bytes) + "; fix the sizes/dimensions or the data");
    DensityGrid g;
    g.nx = nx;
    g.ny = ny;
    g.nz = nz;
    g.values.resize(count);
    unsigned char sample[8];
    for (size_t i = 0; i < count; ++i) {
        std::memcpy(sample, data + i * bytes, bytes);
        if (bigEndian) std::reverse(sample, sample + bytes);
        double v = 0.0;
        switch (type) {
            case DensitySampleType::Uint8:
                v = sample[0] / 255.0;
                break;
            case DensitySampleType::Uint16: {
                uint16_t u = uint16_t(sample[0] | (sample[1] << 8));
                v = u / 65535.0;
                break;
            }
            case DensitySampleType::Float32: {
                uint32_t u = uint32_t(sample[0]) | uint32_t(sample[1]) << 8 |
                             uint32_t(sample[2]) << 16 | uint32_t(sample[3]) << 24;
                float f;
                std::memcpy(&f, &u, 4);
                v = f;
                break;
            }
            case DensitySampleType::Float64: {
                uint64_t u = 0;
                for (int k = 7; k >= 0; --k) u = (u << 8) | sample[k];
                std::memcpy(&v, &u, 8);
                break;
            }
        }
        if (!std::isfinite(v) || v < 0 || v > 1e30)
            throw Error("density grid sample " + std::to_string(i) + " (x " +
                        std::to_string(i % size_t(nx)) + ", y " +
                        std::to_string(i / size_t(nx) % size_t(ny)) + ", z " +
                        std::to_string(i / (size_t(nx) * size_t(ny))) + ") is " +
                        std::to_string(v) +
                        "; densities must be finite and >= 0 (scale them into extinction)");
        g.values[i] = float(v);
    }
    g.maxValue = count ? *std::max_element(g.values.begin(), g.values.end()) : 0.0f;
    return g;
}

std::string trim(const std::string& s) {
    size_t a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
    return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

}  // namespace

float DensityGrid::density(const glm::vec3& p) const {
    if (values.empty()) return 0.0f;
    for (int k = 0; k < 3; ++k)
        if (!(p[k] >= boundsMin[k] && p[k] <= boundsMax[k])) return 0.0f;
    const glm::ivec3 n(nx, ny, nz);
    glm::vec3 extent = boundsMax - boundsMin;
    // Continuous index with sample centres at integers.
    glm::vec3 f = (p - boundsMin) / extent * glm::vec3(n) - 0.5f;
    glm::ivec3 i0, i1;
    glm::vec3 w;
    for (int k = 0; k < 3; ++k) {
        float c = std::clamp(f[k], 0.0f, float(n[k] - 1));
        i0[k] = std::min(int(c), n[k] - 1);
        i1[k] = std::min(i0[k] + 1, n[k] - 1);
        w[k] = c - float(i0[k]);
    }
    auto lerp = [](float a, float b, float t) { return a + (b - a) * t; };
    float c00 = lerp(at(i0.x, i0.y, i0.z), at(i1.x, i0.y, i0.z), w.x);
    float c10 = lerp(at(i0.x, i1.y, i0.z), at(i1.x, i1.y, i0.z), w.x);
    float c01 = lerp(at(i0.x, i0.y, i1.z), at(i1.x, i0.y, i1.z), w.x);
    float c11 = lerp(at(i0.x, i1.y, i1.z), at(i1.x, i1.y, i1.z), w.x);
    return lerp(lerp(c00, c10, w.y), lerp(c01, c11, w.y), w.z);
}

DensitySampleType densitySampleType(const std::string& name) {
    if (name == "uint8") return DensitySampleType::Uint8;
    if (name == "uint16") return DensitySampleType::Uint16;
    if (name == "float32") return DensitySampleType::Float32;
    if (name == "float64") return DensitySampleType::Float64;
    throw Error("density sample type '" + name +
                "' is not supported; use uint8, uint16 (normalised to [0, 1]), float32 or float64");
}

DensityGrid parseRawDensity(const std::string& bytes, int nx, int ny, int nz,
                            DensitySampleType type) {
    return decode(bytes.data(), bytes.size(), nx, ny, nz, type, false);
}

DensityGrid parseNrrdDensity(const std::string& bytes) {
    if (bytes.size() < 8 || bytes.compare(0, 7, "NRRD000") != 0 || bytes[7] < '1' || bytes[7] > '5')
        throw Error(
            "not an NRRD file (it must start with NRRD0001..NRRD0005); write the grid as "
            "NRRD or raw samples");
    // The header ends at the first empty line ("\n\n"; CRLF files: "\r\n\r\n").
    size_t end = bytes.find("\n\n");
    size_t dataStart = end == std::string::npos ? end : end + 2;
    size_t crlf = bytes.find("\r\n\r\n");
    if (crlf != std::string::npos && (end == std::string::npos || crlf < end)) {
        end = crlf;
        dataStart = crlf + 4;
    }
    if (end == std::string::npos || end > 65536)
        throw Error(
            "NRRD header has no end (an empty line must separate header and data; "
            "detached headers are not supported)");
    std::map<std::string, std::string> fields;
    std::istringstream header(bytes.substr(0, end));
    std::string line;
    std::getline(header, line);  // magic
    while (std::getline(header, line)) {
        line = trim(line);
        if (line.empty() || line[0] == '#') continue;
        if (line.find(":=") != std::string::npos) continue;  // key/value pairs: not used
        size_t colon = line.find(": ");
        if (colon == std::string::npos)
            throw Error("NRRD header line '" + line.substr(0, 60) +
                        "' is not 'field: value'; fix the header");
        fields[line.substr(0, colon)] = trim(line.substr(colon + 2));
    }
    auto field = [&](const char* key) -> const std::string& {
        auto it = fields.find(key);
        if (it == fields.end())
            throw Error(std::string("NRRD header has no '") + key + "' field; add it");
        return it->second;
    };
    if (fields.count("data file") || fields.count("datafile"))
        throw Error(
            "NRRD 'data file' (a detached header) is not supported; put the samples "
            "after the header in one file");
    const std::string& typeName = field("type");
    DensitySampleType type;
    if (typeName == "uchar" || typeName == "unsigned char" || typeName == "uint8" ||
        typeName == "uint8_t")
        type = DensitySampleType::Uint8;
    else if (typeName == "ushort" || typeName == "unsigned short" || typeName == "uint16" ||
             typeName == "uint16_t" || typeName == "unsigned short int")
        type = DensitySampleType::Uint16;
    else if (typeName == "float")
        type = DensitySampleType::Float32;
    else if (typeName == "double")
        type = DensitySampleType::Float64;
    else
        throw Error(
            "NRRD type '" + typeName +
            "' is not supported; use uchar, ushort (normalised to [0, 1]), float or double");
    if (field("dimension") != "3")
        throw Error("NRRD dimension is '" + field("dimension") + "'; a density grid has 3");
    const std::string& encoding = field("encoding");
    if (encoding != "raw")
        throw Error("NRRD encoding '" + encoding +
                    "' is not supported; write it with 'encoding: raw' (uncompressed)");
    bool big = false;
    if (sampleBytes(type) > 1) {
        const std::string& endian = field("endian");
        if (endian != "little" && endian != "big")
            throw Error("NRRD endian is '" + endian + "'; expected little or big");
        big = endian == "big";
    }
    std::istringstream sizes(field("sizes"));
    long long n[3];
    for (long long& v : n) {
        if (!(sizes >> v))
            throw Error("NRRD sizes '" + field("sizes") + "' must be 3 integers (x y z)");
    }
    std::string extra;
    if (sizes >> extra) throw Error("NRRD sizes '" + field("sizes") + "' has more than 3 entries");
    for (long long v : n)
        if (v < 1 || v > kMaxDensityDim)
            throw Error("NRRD sizes entry " + std::to_string(v) + " is outside 1.." +
                        std::to_string(kMaxDensityDim) + "; resample the grid");
    return decode(bytes.data() + dataStart, bytes.size() - dataStart, int(n[0]), int(n[1]),
                  int(n[2]), type, big);
}

}  // namespace mirage
