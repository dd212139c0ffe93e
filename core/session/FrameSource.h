#pragma once
// Sequential frame access, one interface for every source of frames: a session camera
// (core/session/Session.h: openCameraFrames), a video file or image folder (openFrames), a list
// of image files, folders and videos sampled for calibration (openFrameList), and a live camera
// (core/capture/V4l2Camera.h). Frames are 8-bit BGR, sRGB-encoded, as cameras deliver them.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace mirage {

class FrameSource {
public:
    virtual ~FrameSource() = default;
    // Next frame as 8-bit BGR (sRGB-encoded, as cameras deliver it); false at the end. True with
    // an empty image: the frame is lost (lastProblem() says why); callers must check.
    virtual bool read(cv::Mat& bgr) = 0;
    virtual int frameCount() const = 0;  // -1 if unknown
    // Time of the frame last returned by read(), seconds; nullopt if the source has no clock.
    virtual std::optional<double> lastTimestamp() const { return std::nullopt; }
    // About the frame last read: why it is lost when read() returned true with an EMPTY image
    // (its bytes are damaged or missing; the frame keeps its place so later frames keep their
    // numbers), or a remark about a delivered image (it repeats the previous frame exactly).
    // Empty when nothing is wrong.
    virtual std::string lastProblem() const { return {}; }
    // What the frame last read is called in messages: its image file's name, or "VIDEO#N" for
    // frame N (from 0) of a video file. Empty for sources without names (a live camera).
    virtual std::string lastName() const { return {}; }
    // Frames the device itself dropped so far (a V4L2 driver's sequence-number gaps); 0 for
    // recorded sources.
    virtual int64_t deviceDroppedFrames() const { return 0; }
};

// By extension: .png .jpg .jpeg .bmp .tif .tiff .pgm .ppm .webp.
bool isImageFile(const std::filesystem::path& p);
// By extension: .mp4 .mkv .avi .mov .webm .m4v .mpg .mpeg.
bool isVideoFile(const std::filesystem::path& p);

// A plain video file (any format FFmpeg reads; mirage's MJPEG Matroska recordings frame-exactly)
// or image folder (files sorted by the number in their name, else by name), outside a session.
// Throws FileError if it cannot be opened.
std::unique_ptr<FrameSource> openFrames(const std::filesystem::path& videoOrFolder);

struct FrameListOptions {
    // Videos: deliver every Nth frame; 0 = automatic (about maxVideoFrames frames per video).
    int videoStep = 0;
    int maxVideoFrames = 120;
    // Deliver every frame of videos (where motion is measured between consecutive frames, or
    // frames of two inputs are paired by order). Overrides videoStep.
    bool allVideoFrames = false;
};

// INPUT... as one stream, in the order given: each input is an image file, a folder of images
// (openFrames' order; a folder without images is an error) or a video (sampled by `options`).
// Throws mirage::Error for an empty list and FileError naming the input that does not exist,
// is neither an image nor a video, or (while reading) cannot be decoded or holds no frame.
// Timestamps: a video's own clock; image files have none.
std::unique_ptr<FrameSource> openFrameList(const std::vector<std::string>& inputs,
                                           const FrameListOptions& options);

}  // namespace mirage
