#include "core/capture/CaptureFormat.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace mirage {

const char* pixelFormatName(PixelFormat f) {
    return f == PixelFormat::Yuyv ? "YUYV" : "MJPEG";
}

double steadySeconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

std::optional<CaptureMode> chooseCaptureMode(const std::vector<CaptureMode>& all,
                                             const CaptureRequest& req) {
    std::vector<CaptureMode> modes;
    for (const auto& m : all) {
        if (m.width <= 0 || m.height <= 0 || !(m.fps > 0)) continue;
        if (req.format == CaptureRequest::Format::Mjpeg && m.format != PixelFormat::Mjpeg) continue;
        if (req.format == CaptureRequest::Format::Yuyv && m.format != PixelFormat::Yuyv) continue;
        modes.push_back(m);
    }
    if (modes.empty()) return std::nullopt;

    // 1. Size: exact, else nearest in log-area, with aspect-ratio changes weighted double
    //    (a 4:3 mode for a 16:9 request crops or stretches the view).
    const double wantArea = double(req.width) * req.height;
    const double wantAspect = double(req.width) / std::max(1, req.height);
    auto sizeCost = [&](const CaptureMode& m) {
        if (m.width == req.width && m.height == req.height) return 0.0;
        const double area = double(m.width) * m.height;
        const double aspect = double(m.width) / m.height;
        return 1e-6 + std::abs(std::log(area / wantArea)) +
               2 * std::abs(std::log(aspect / wantAspect));
    };
    const auto bestSize = *std::min_element(
        modes.begin(), modes.end(), [&](auto& a, auto& b) { return sizeCost(a) < sizeCost(b); });
    std::vector<CaptureMode> atSize;
    for (const auto& m : modes)
        if (m.width == bestSize.width && m.height == bestSize.height) atSize.push_back(m);

    // 2. Rate and format: among modes reaching the wanted rate (1% slack for 29.97 vs 30), the
    //    preferred format (Auto: YUYV) at the lowest such rate; if none reaches it, the fastest.
    const auto meets = [&](const CaptureMode& m) { return m.fps >= req.fps * 0.99; };
    const auto formatRank = [&](const CaptureMode& m) {
        return m.format == PixelFormat::Yuyv ? 0 : 1;
    };
    std::vector<CaptureMode> fast;
    for (const auto& m : atSize)
        if (meets(m)) fast.push_back(m);
    if (!fast.empty())
        return *std::min_element(fast.begin(), fast.end(), [&](auto& a, auto& b) {
            if (formatRank(a) != formatRank(b)) return formatRank(a) < formatRank(b);
            return a.fps < b.fps;
        });
    return *std::min_element(atSize.begin(), atSize.end(), [&](auto& a, auto& b) {
        if (a.fps != b.fps) return a.fps > b.fps;
        return formatRank(a) < formatRank(b);
    });
}

bool convertToBgr(const RawFrame& f, cv::Mat& bgr) {
    bgr.release();
    if (!f.bytes || f.width <= 0 || f.height <= 0) return false;
    if (f.format == PixelFormat::Yuyv) {
        const int stride = f.bytesPerLine > 0 ? f.bytesPerLine : 2 * f.width;
        if (f.width % 2 != 0 || stride < 2 * f.width) return false;
        // The last row needs only its pixels, not a full stride.
        if (f.size < size_t(stride) * size_t(f.height - 1) + size_t(2 * f.width)) return false;
        const cv::Mat yuyv(f.height, f.width, CV_8UC2, const_cast<uint8_t*>(f.bytes),
                           size_t(stride));
        cv::cvtColor(yuyv, bgr, cv::COLOR_YUV2BGR_YUYV);
        return true;
    }
    if (f.size < 4) return false;
    const cv::Mat encoded(1, int(f.size), CV_8U, const_cast<uint8_t*>(f.bytes));
    try {
        bgr = cv::imdecode(encoded, cv::IMREAD_COLOR);
    } catch (const cv::Exception&) {
        bgr.release();
    }
    if (bgr.empty() || bgr.cols != f.width || bgr.rows != f.height) {
        bgr.release();
        return false;
    }
    return true;
}

std::vector<uint8_t> bgrToYuyv(const cv::Mat& bgr) {
    CV_Assert(bgr.type() == CV_8UC3 && bgr.cols % 2 == 0);
    std::vector<uint8_t> out(size_t(bgr.rows) * size_t(bgr.cols) * 2);
    auto clamp8 = [](double v) { return uint8_t(std::clamp(std::lround(v), 0L, 255L)); };
    // BT.601 limited range (Y in 16..235, U/V in 16..240), the inverse of OpenCV's YUV2BGR.
    auto luma = [](double r, double g, double b) {
        return 16 + 0.256788 * r + 0.504129 * g + 0.097906 * b;
    };
    for (int y = 0; y < bgr.rows; ++y) {
        const cv::Vec3b* row = bgr.ptr<cv::Vec3b>(y);
        uint8_t* o = out.data() + size_t(y) * size_t(bgr.cols) * 2;
        for (int x = 0; x < bgr.cols; x += 2) {
            const cv::Vec3b a = row[x], b = row[x + 1];
            const double r = (a[2] + b[2]) / 2.0, g = (a[1] + b[1]) / 2.0, bl = (a[0] + b[0]) / 2.0;
            o[2 * x + 0] = clamp8(luma(a[2], a[1], a[0]));
            o[2 * x + 1] = clamp8(128 - 0.148223 * r - 0.290993 * g + 0.439216 * bl);
            o[2 * x + 2] = clamp8(luma(b[2], b[1], b[0]));
            o[2 * x + 3] = clamp8(128 + 0.439216 * r - 0.367788 * g - 0.071427 * bl);
        }
    }
    return out;
}

double FrameClock::stamp(const RawFrame& f, double hostSeconds) {
    if (f.sequence >= 0) {
        if (lastSequence_ >= 0 && f.sequence > lastSequence_ + 1)
            dropped_ += int(f.sequence - lastSequence_ - 1);
        lastSequence_ = f.sequence;
    }
    double t;
    if (useDevice_ && f.deviceSeconds >= 0 && (first_ || f.deviceSeconds > last_)) {
        t = f.deviceSeconds;
    } else {
        // No usable driver clock (none, or it went backwards): the host clock from now on.
        // Both are CLOCK_MONOTONIC on Linux, so the switch does not jump.
        useDevice_ = false;
        t = first_ ? hostSeconds : std::max(hostSeconds, last_ + 1e-6);
    }
    first_ = false;
    last_ = t;
    return t;
}

}  // namespace mirage
