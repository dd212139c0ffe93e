#pragma once
// Frames of an MJPEG video that mirage reads itself, container and JPEG alike, so that a frame is
// either exactly the image that was written or reported lost with the reason, never a concealed
// or stale image (FFmpeg's MJPEG decoder conceals damaged data and can repeat the previous
// picture). Matroska (MatroskaFrames.h) and AVI (AviFrames.h) implement it; openStrictVideo picks
// the reader by the file's first bytes.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace mirage {

class StrictVideoFrames {
public:
    struct Frame {
        cv::Mat bgr;          // 8-bit BGR, sRGB-encoded; empty if lost
        double seconds = 0;   // the container's time of the frame
        std::string problem;  // why it is lost; or, with an image, a remark (exact repeat)
    };
    virtual ~StrictVideoFrames() = default;
    // True if this reader decodes the video (MJPEG in a layout it reads; else FFmpeg must).
    virtual bool supported() const = 0;
    // Frame numbers 0 .. count()-1 (lost frames included).
    virtual int count() const = 0;
    // Frame `position`; positions must be asked for in increasing order.
    virtual Frame frame(int position) = 0;
    // Damage in the container (what was found, where); empty if none.
    virtual std::string containerProblem() const = 0;
};

// The strict reader of a Matroska or AVI file (by its magic bytes, whatever the extension) if it
// holds MJPEG video; nullptr for other files and codecs (read through FFmpeg). Throws FileError
// if the file cannot be opened.
std::unique_ptr<StrictVideoFrames> openStrictVideo(const std::filesystem::path& path);

// The checks every strict reader makes on a frame's bytes: a JPEG decoded without any libjpeg
// warning, of the track's size, and flagged when it repeats the previous frame byte for byte.
class StrictJpegFrames {
public:
    // Expected image size (0: not known).
    void setTrackSize(int width, int height) {
        width_ = width;
        height_ = height;
    }
    StrictVideoFrames::Frame decode(int position, std::vector<uint8_t>& bytes);

private:
    int width_ = 0, height_ = 0;
    std::vector<uint8_t> previousBytes_;
    int previousPosition_ = -1;
};

}  // namespace mirage
