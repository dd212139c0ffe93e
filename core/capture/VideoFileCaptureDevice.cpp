#include "core/capture/VideoFileCaptureDevice.h"

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/capture/CaptureFormat.h"

namespace mirage {

VideoFileCaptureDevice::VideoFileCaptureDevice(const std::filesystem::path& p)
    : VideoFileCaptureDevice(p, Options{}) {}

VideoFileCaptureDevice::VideoFileCaptureDevice(const std::filesystem::path& p, Options opts)
    : path_(p), opts_(std::move(opts)), source_(openFrames(p)) {
    if (!(opts_.fps > 0)) throw Error("VideoFileCaptureDevice: fps must be positive");
    // A lost frame (damaged bytes) is skipped, as a camera drops one.
    while (source_->read(first_) && first_.empty()) {
    }
    if (first_.empty()) throw FileError(p.string(), "holds no frames to play as a camera");
    firstPending_ = true;
}

std::string VideoFileCaptureDevice::name() const {
    return "video file " + path_.string();
}

std::vector<CaptureMode> VideoFileCaptureDevice::modes() {
    std::vector<CaptureMode> m = {{PixelFormat::Mjpeg, first_.cols, first_.rows, opts_.fps}};
    // YUYV needs an even width (two pixels share their chroma).
    if (first_.cols % 2 == 0) m.push_back({PixelFormat::Yuyv, first_.cols, first_.rows, opts_.fps});
    return m;
}

CaptureMode VideoFileCaptureDevice::configure(const CaptureMode& mode) {
    for (const auto& m : modes())
        if (m.format == mode.format && m.width == mode.width && m.height == mode.height) {
            mode_ = m;  // like a driver, keep the rate it can do
            configured_ = true;
            return mode_;
        }
    throw Error(name() + ": mode " + pixelFormatName(mode.format) + " " +
                std::to_string(mode.width) + "x" + std::to_string(mode.height) + " not offered");
}

void VideoFileCaptureDevice::start() {
    if (!configured_) throw Error(name() + ": start() before configure()");
    started_ = true;
}

bool VideoFileCaptureDevice::dequeue(RawFrame& f, int) {
    if (!started_) throw Error(name() + ": dequeue before start()");
    cv::Mat bgr;
    if (firstPending_) {
        bgr = first_;
        firstPending_ = false;
    } else {
        do {
            if (!source_->read(bgr)) return false;
        } while (bgr.empty());  // lost frames are dropped, as a camera drops them
    }
    if (bgr.size() != first_.size()) throw Error(name() + ": frame size changed mid-stream");
    if (mode_.format == PixelFormat::Mjpeg) {
        cv::imencode(".jpg", bgr, buffer_, {cv::IMWRITE_JPEG_QUALITY, 90});
        f.bytesPerLine = 0;
    } else {
        const std::vector<uint8_t> packed = bgrToYuyv(bgr);
        const size_t row = size_t(bgr.cols) * 2, stride = row + size_t(opts_.yuyvStridePadding);
        buffer_.assign(stride * size_t(bgr.rows), 0);
        for (int y = 0; y < bgr.rows; ++y)
            std::copy_n(packed.data() + size_t(y) * row, row, buffer_.data() + size_t(y) * stride);
        f.bytesPerLine = int(stride);
    }
    f.format = mode_.format;
    f.width = bgr.cols;
    f.height = bgr.rows;
    f.bytes = buffer_.data();
    f.size = buffer_.size();
    f.sequence = sequence_;
    f.deviceSeconds =
        opts_.deviceTimestamps ? opts_.startSeconds + double(sequence_) / opts_.fps : -1.0;
    ++sequence_;
    // Simulated driver drop: the sequence number after a listed one is skipped.
    if (dropIndex_ < opts_.dropAfter.size() && f.sequence == opts_.dropAfter[dropIndex_]) {
        ++sequence_;
        ++dropIndex_;
    }
    return true;
}

void VideoFileCaptureDevice::stop() {
    started_ = false;
}

}  // namespace mirage
