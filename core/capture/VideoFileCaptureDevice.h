#pragma once
// A recorded video (or image folder) posing as a camera: it offers MJPEG and YUYV at the
// video's size and rate and delivers frames re-encoded to the chosen format, with a simulated
// monotonic driver clock and sequence numbers. It lets the capture path (mode choice,
// conversion, timestamps, recording) run without a webcam: in tests, and as `--fake-camera`.
#include <filesystem>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "core/capture/CaptureDevice.h"
#include "core/session/Session.h"

namespace mirage {

class VideoFileCaptureDevice final : public CaptureDevice {
public:
    struct Options {
        double fps = 30;              // the rate it claims and stamps frames with
        double startSeconds = 100.0;  // device clock at the first frame
        // Deliver the first frames with these sequence gaps (e.g. {2} = frame 2 "dropped"):
        // exercises the dropped-frame count.
        std::vector<int64_t> dropAfter;
        int yuyvStridePadding = 0;  // extra bytes per YUYV row, like drivers with aligned rows
        bool deviceTimestamps = true;
    };
    VideoFileCaptureDevice(const std::filesystem::path& videoOrFolder, Options opts);
    VideoFileCaptureDevice(const std::filesystem::path& videoOrFolder);

    std::string name() const override;
    std::vector<CaptureMode> modes() override;
    CaptureMode configure(const CaptureMode& mode) override;
    void start() override;
    bool dequeue(RawFrame& frame, int timeoutMs) override;
    void stop() override;

private:
    std::filesystem::path path_;
    Options opts_;
    std::unique_ptr<FrameSource> source_;
    cv::Mat first_;  // read ahead to learn the size
    bool firstPending_ = false;
    CaptureMode mode_;
    bool configured_ = false, started_ = false;
    int64_t sequence_ = 0;
    size_t dropIndex_ = 0;
    std::vector<uint8_t> buffer_;
};

}  // namespace mirage
