#pragma once
// A minimal Matroska (MKV) muxer for one MJPEG video track, written for crash-safety:
//
//   EBML header | Segment (size "unknown") { Info, Tracks, Cluster, Cluster, ... }
//
// Every frame is one Cluster holding one SimpleBlock with the JPEG bytes, written with plain
// write(2) calls (no user-space buffer) as soon as append() is called. A process killed at any
// point therefore leaves a file whose complete clusters are all decodable by FFmpeg/OpenCV;
// only the cluster being written at that moment is cut short, and demuxers stop there. The
// Segment is opened with an unknown size so the file is valid before close(); close() then
// patches in the real Segment size and the Duration (reserved as an EBML Void element up front).
//
// Timestamps: Matroska ticks of 1 ms (TimestampScale 1,000,000 ns), relative to the first
// frame. The exact per-frame times live in the session's frames.csv, not here.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace mirage {

class MatroskaWriter {
public:
    // Creates (truncates) `path`. Nothing is written until the first frame, because the track
    // header needs the frame size. Throws FileError if the file cannot be created.
    MatroskaWriter(const std::filesystem::path& path, double fps, int jpegQuality);
    ~MatroskaWriter();
    MatroskaWriter(const MatroskaWriter&) = delete;
    MatroskaWriter& operator=(const MatroskaWriter&) = delete;

    // Encodes an 8-bit BGR image (sRGB-encoded) as JPEG and appends it as one cluster.
    // `seconds` is the frame time; the stored time is forced to increase by >= 1 ms per frame.
    // All frames must have the size of the first. fsyncEachFrame also survives power loss.
    void append(const cv::Mat& bgr, double seconds, bool fsyncEachFrame = false);
    // Appends an already encoded JPEG (used by tests to write deliberately odd files).
    void appendJpeg(const std::vector<uint8_t>& jpeg, int width, int height, double seconds,
                    bool fsyncEachFrame = false);
    // Patches Segment size and Duration, closes the file. Safe to call twice.
    void close();

    int framesWritten() const { return frames_; }
    const std::filesystem::path& path() const { return path_; }

private:
    void writeHeader(int width, int height);
    void writeAll(const std::string& bytes);
    void pwriteAll(const std::string& bytes, uint64_t offset);

    std::filesystem::path path_;
    double fps_;
    int quality_;
    int fd_ = -1;
    int width_ = 0, height_ = 0;
    int frames_ = 0;
    uint64_t fileSize_ = 0;
    uint64_t segmentSizeOffset_ = 0;  // where the 8-byte Segment size lives
    uint64_t segmentDataStart_ = 0;
    uint64_t durationOffset_ = 0;  // where the reserved Void for Duration lives
    int64_t firstMs_ = 0, lastMs_ = -1;
    double firstSeconds_ = 0;
};

}  // namespace mirage
