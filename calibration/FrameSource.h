#pragma once
// Where calibration frames come from: image files, folders of images, or video files (sampled).
// Frames are 8-bit BGR, sRGB-encoded, as OpenCV decodes them. The live camera source is in the
// app (it wraps core/capture), behind the same interface.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace mirage::calib {

struct InputFrame {
    cv::Mat bgr;             // CV_8UC3, sRGB-encoded
    std::string name;        // file name, or "video.mp4#123" for frame 123 of a video
    double timeSeconds = 0;  // presentation time (videos, cameras); images: index / 30
};

class FrameSource {
public:
    virtual ~FrameSource() = default;
    // Next frame; false at the end. Throws mirage::FileError on an unreadable file.
    virtual bool next(InputFrame& frame) = 0;
    // Total frames it will deliver if known, else -1.
    virtual int frameCountHint() const { return -1; }
    // True for live sources (a camera), where frames keep coming and cannot be revisited.
    virtual bool isLive() const { return false; }
};

struct FrameSourceOptions {
    // Videos: use every Nth frame; 0 = automatic (about maxVideoFrames frames over the video).
    int videoStep = 0;
    int maxVideoFrames = 120;
    // Deliver every frame of videos (the wizard's replay, where stillness is measured between
    // consecutive frames). Overrides videoStep.
    bool allVideoFrames = false;
};

bool isImageFile(const std::filesystem::path& p);  // by extension (.png .jpg .jpeg .bmp .tif...)
bool isVideoFile(const std::filesystem::path& p);  // by extension (.mp4 .mkv .avi .mov .webm)

// Opens INPUT... as one stream: each input is an image file, a folder (its images, sorted by
// name; a folder without images is an error) or a video. Throws mirage::FileError naming the
// input that does not exist or is neither.
std::unique_ptr<FrameSource> openFrameSource(const std::vector<std::string>& inputs,
                                             const FrameSourceOptions& options);

}  // namespace mirage::calib
