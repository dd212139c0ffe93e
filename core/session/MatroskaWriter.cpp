#include "core/session/MatroskaWriter.h"
#include "core/session/MatroskaScanner.h"

#include <fcntl.h>
#include <unistd.h>
#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>

#include <opencv2/imgcodecs.hpp>

#include "core/Error.h"

namespace mirage {

namespace {

// Element IDs (Matroska specification, RFC 9559), written with their marker bits.
constexpr uint32_t kEbml = 0x1A45DFA3, kEbmlVersion = 0x4286, kEbmlReadVersion = 0x42F7,
                   kEbmlMaxIdLength = 0x42F2, kEbmlMaxSizeLength = 0x42F3, kDocType = 0x4282,
                   kDocTypeVersion = 0x4287, kDocTypeReadVersion = 0x4285;
constexpr uint32_t kSegment = 0x18538067, kInfo = 0x1549A966, kTimestampScale = 0x2AD7B1,
                   kDuration = 0x4489, kMuxingApp = 0x4D80, kWritingApp = 0x5741, kVoid = 0xEC;
constexpr uint32_t kTracks = 0x1654AE6B, kTrackEntry = 0xAE, kTrackNumber = 0xD7,
                   kTrackUid = 0x73C5, kTrackType = 0x83, kFlagLacing = 0x9C, kCodecId = 0x86,
                   kDefaultDuration = 0x23E383, kVideo = 0xE0, kPixelWidth = 0xB0,
                   kPixelHeight = 0xBA;
constexpr uint32_t kCluster = 0x1F43B675, kTimestamp = 0xE7, kSimpleBlock = 0xA3, kCrc32 = 0xBF;

constexpr uint64_t kTimestampScaleNs = 1000000;  // 1 tick = 1 ms

std::string id(uint32_t v) {
    std::string s;
    const int bytes = v > 0xFFFFFF ? 4 : v > 0xFFFF ? 3 : v > 0xFF ? 2 : 1;
    for (int i = bytes - 1; i >= 0; --i) s += char((v >> (8 * i)) & 0xFF);
    return s;
}

// EBML variable-length size: the shortest form; all-ones values are reserved ("unknown").
std::string size(uint64_t n) {
    int len = 1;
    while (len < 8 && n >= (uint64_t(1) << (7 * len)) - 1) ++len;
    std::string s(size_t(len), '\0');
    for (int i = len - 1; i >= 0; --i, n >>= 8) s[size_t(i)] = char(n & 0xFF);
    s[0] = char(uint8_t(s[0]) | (0x80 >> (len - 1)));
    return s;
}

// Fixed 8-byte size form (used where the value is patched later).
std::string size8(uint64_t n) {
    std::string s(8, '\0');
    for (int i = 7; i >= 1; --i, n >>= 8) s[size_t(i)] = char(n & 0xFF);
    s[0] = 0x01;
    return s;
}

std::string element(uint32_t elementId, const std::string& payload) {
    return id(elementId) + size(payload.size()) + payload;
}

std::string uintElement(uint32_t elementId, uint64_t v) {
    std::string p;
    do {
        p.insert(p.begin(), char(v & 0xFF));
        v >>= 8;
    } while (v);
    return element(elementId, p);
}

std::string floatElement(uint32_t elementId, double v) {
    const uint64_t bits = std::bit_cast<uint64_t>(v);
    std::string p(8, '\0');
    for (int i = 0; i < 8; ++i) p[size_t(i)] = char((bits >> (8 * (7 - i))) & 0xFF);
    return element(elementId, p);
}

}  // namespace

MatroskaWriter::MatroskaWriter(const std::filesystem::path& path, double fps, int jpegQuality)
    : path_(path), fps_(fps), quality_(std::clamp(jpegQuality, 1, 100)) {
    if (!(fps > 0 && std::isfinite(fps)))
        throw FileError(path.string(), "frame rate must be positive, got " + std::to_string(fps));
    fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0)
        throw FileError(path.string(), std::string("cannot create video file: ") +
                                           std::strerror(errno) + " (is the folder writable?)");
}

MatroskaWriter::~MatroskaWriter() {
    try {
        close();
    } catch (...) {
        // A destructor must not throw; the file is still valid without the patched sizes.
    }
}

void MatroskaWriter::writeAll(const std::string& bytes) {
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            throw FileError(path_.string(),
                            std::string("write failed: ") + std::strerror(errno) + " (disk full?)");
        }
        done += size_t(n);
    }
    fileSize_ += bytes.size();
}

void MatroskaWriter::pwriteAll(const std::string& bytes, uint64_t offset) {
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n =
            ::pwrite(fd_, bytes.data() + done, bytes.size() - done, off_t(offset + done));
        if (n < 0) {
            if (errno == EINTR) continue;
            throw FileError(path_.string(), std::string("write failed: ") + std::strerror(errno));
        }
        done += size_t(n);
    }
}

void MatroskaWriter::writeHeader(int width, int height) {
    const std::string ebml =
        element(kEbml, uintElement(kEbmlVersion, 1) + uintElement(kEbmlReadVersion, 1) +
                           uintElement(kEbmlMaxIdLength, 4) + uintElement(kEbmlMaxSizeLength, 8) +
                           element(kDocType, "matroska") + uintElement(kDocTypeVersion, 4) +
                           uintElement(kDocTypeReadVersion, 2));
    // Duration is unknown until close(): reserve its 11 bytes (ID 2 + size 1 + float 8) as Void.
    const std::string durationReserve = id(kVoid) + size(9) + std::string(9, '\0');
    const std::string infoHead = uintElement(kTimestampScale, kTimestampScaleNs) +
                                 element(kMuxingApp, "mirage") + element(kWritingApp, "mirage");
    const std::string info = element(kInfo, infoHead + durationReserve);
    const std::string video = element(kVideo, uintElement(kPixelWidth, uint64_t(width)) +
                                                  uintElement(kPixelHeight, uint64_t(height)));
    const std::string track = element(
        kTrackEntry, uintElement(kTrackNumber, 1) + uintElement(kTrackUid, 1) +
                         uintElement(kTrackType, 1) + uintElement(kFlagLacing, 0) +
                         element(kCodecId, "V_MJPEG") +
                         uintElement(kDefaultDuration, uint64_t(std::llround(1e9 / fps_))) + video);
    const std::string tracks = element(kTracks, track);

    std::string out = ebml;
    out += id(kSegment);
    segmentSizeOffset_ = out.size();
    out += std::string("\x01\xFF\xFF\xFF\xFF\xFF\xFF\xFF", 8);  // unknown size
    segmentDataStart_ = out.size();
    // Info's payload starts after its ID (4 bytes) and size; the Void sits at its end.
    durationOffset_ = out.size() + info.size() - durationReserve.size();
    out += info + tracks;
    writeAll(out);
}

void MatroskaWriter::append(const cv::Mat& bgr, double seconds, bool fsyncEachFrame) {
    if (bgr.empty() || bgr.depth() != CV_8U || (bgr.channels() != 3 && bgr.channels() != 1))
        throw Error("MatroskaWriter::append: expected an 8-bit BGR or grey image for " +
                    path_.string());
    std::vector<uint8_t> jpeg;
    if (!cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, quality_}))
        throw FileError(path_.string(), "JPEG encoding failed");
    appendJpeg(jpeg, bgr.cols, bgr.rows, seconds, fsyncEachFrame);
}

void MatroskaWriter::appendJpeg(const std::vector<uint8_t>& jpeg, int width, int height,
                                double seconds, bool fsyncEachFrame) {
    if (fd_ < 0) throw FileError(path_.string(), "append after close");
    if (!std::isfinite(seconds))
        throw Error("MatroskaWriter::append: frame time is not finite (" + path_.string() + ")");
    if (frames_ == 0) {
        width_ = width;
        height_ = height;
        firstSeconds_ = seconds;
        writeHeader(width, height);
    } else if (width != width_ || height != height_) {
        throw FileError(path_.string(), "frame size changed from " + std::to_string(width_) + "x" +
                                            std::to_string(height_) + " to " +
                                            std::to_string(width) + "x" + std::to_string(height) +
                                            " (one video holds one size)");
    }
    // Cluster times must increase: equal or backwards camera times are nudged by 1 ms.
    int64_t ms = std::llround((seconds - firstSeconds_) * 1000.0);
    ms = std::max(ms, lastMs_ + 1);
    lastMs_ = ms;

    // SimpleBlock: track number (vint 1), int16 time relative to the cluster (0), flags
    // (0x80 = keyframe: every JPEG is), then the frame bytes.
    std::string block = std::string("\x81\x00\x00\x80", 4);
    block.append(reinterpret_cast<const char*>(jpeg.data()), jpeg.size());
    // A CRC-32 element first in the cluster covers the rest of it: any damaged byte of the frame
    // is detected when it is read (JPEG decoding alone cannot see a changed coefficient value).
    const std::string payload =
        uintElement(kTimestamp, uint64_t(ms)) + element(kSimpleBlock, block);
    const uint32_t crc =
        crc32Ieee(reinterpret_cast<const uint8_t*>(payload.data()), payload.size());
    std::string crcBytes(4, '\0');
    for (int i = 0; i < 4; ++i) crcBytes[size_t(i)] = char((crc >> (8 * i)) & 0xFF);
    const std::string cluster = element(kCluster, element(kCrc32, crcBytes) + payload);
    writeAll(cluster);
    if (fsyncEachFrame && ::fsync(fd_) != 0)
        throw FileError(path_.string(), std::string("fsync failed: ") + std::strerror(errno));
    ++frames_;
}

void MatroskaWriter::close() {
    if (fd_ < 0) return;
    const int fd = fd_;
    try {
        if (frames_ > 0) {
            pwriteAll(size8(fileSize_ - segmentDataStart_), segmentSizeOffset_);
            // Duration (in ticks, a float): last frame time plus one frame period.
            const double durationMs = double(lastMs_) + 1000.0 / fps_;
            pwriteAll(floatElement(kDuration, durationMs), durationOffset_);
        }
        if (::fsync(fd) != 0)
            throw FileError(path_.string(), std::string("fsync failed: ") + std::strerror(errno));
    } catch (...) {
        ::close(fd);
        fd_ = -1;
        throw;
    }
    fd_ = -1;
    if (::close(fd) != 0)
        throw FileError(path_.string(), std::string("close failed: ") + std::strerror(errno));
}

}  // namespace mirage
