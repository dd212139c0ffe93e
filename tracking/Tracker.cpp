#include "tracking/Tracker.h"

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

namespace mirage::tracking {
namespace {
double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

double imageSharpness(const cv::Mat& grey) {
    if (grey.empty()) return 0;
    cv::Mat gx, gy;
    cv::Sobel(grey, gx, CV_32F, 1, 0, 3, 1.0 / 8.0);
    cv::Sobel(grey, gy, CV_32F, 0, 1, 3, 1.0 / 8.0);
    // Histograms instead of sorting: derivatives in 0.25-level bins, intensity in levels.
    std::array<std::vector<int>, 4> gh;
    for (auto& h : gh) h.assign(2048, 0);
    std::vector<int> ih(256, 0);
    const float r = float(M_SQRT1_2);
    auto bin = [](float v) { return size_t(std::min(2047, int(std::abs(v) * 4))); };
    for (int y = 0; y < grey.rows; ++y) {
        const float* a = gx.ptr<float>(y);
        const float* b = gy.ptr<float>(y);
        const uint8_t* g = grey.ptr<uint8_t>(y);
        for (int x = 0; x < grey.cols; ++x) {
            ++gh[0][bin(a[x])];
            ++gh[1][bin(b[x])];
            ++gh[2][bin(r * (a[x] + b[x]))];
            ++gh[3][bin(r * (a[x] - b[x]))];
            ++ih[g[x]];
        }
    }
    const double n = double(grey.total());
    auto quantile = [&](const std::vector<int>& h, double q) {
        double acc = 0;
        for (size_t i = 0; i < h.size(); ++i) {
            acc += h[i];
            if (acc >= q * n) return double(i);
        }
        return double(h.size() - 1);
    };
    const double range = quantile(ih, 0.99) - quantile(ih, 0.01);
    if (range < 8) return 0;
    double weakest = 1e9;
    for (const auto& h : gh) weakest = std::min(weakest, quantile(h, 0.995) / 4.0);
    return weakest / range;
}

Tracker::Tracker(Board board, CameraIntrinsics camera, TrackerOptions options)
    : options_(options),
      detector_(options.detector),
      estimator_(std::move(board), std::move(camera), options.pose),
      filter_(options.filter),
      oneEuro_(options.oneEuro) {}

TrackedFrame Tracker::process(const cv::Mat& image, double t) {
    TrackedFrame f;
    f.t = t;
    cv::Mat grey;
    if (image.type() == CV_8UC3)
        cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
    else
        grey = image;
    auto t0 = std::chrono::steady_clock::now();
    f.detections = detector_.detect(grey);
    f.detectMs = msSince(t0);

    t0 = std::chrono::steady_clock::now();
    std::optional<Pose> prior;
    if (lastOk_ && t - lastOkT_ <= options_.priorMaxAgeS && t >= lastOkT_) prior = lastOk_;
    f.estimate = estimator_.estimate(f.detections, prior);
    if (f.estimate.state == TrackingState::NoTags) {
        f.sharpness = imageSharpness(grey);
        if (f.sharpness > 0 && f.sharpness < options_.minSharpness) {
            f.estimate.state = TrackingState::TooBlurred;
            char buf[160];
            std::snprintf(buf, sizeof buf,
                          "no tag found and the image is blurred (sharpness %.3f < %.3f)",
                          f.sharpness, options_.minSharpness);
            f.estimate.reason = buf;
        }
    }
    f.poseMs = msSince(t0);

    t0 = std::chrono::steady_clock::now();
    if (f.estimate.state == TrackingState::Ok) {
        lastOk_ = f.estimate.pose;
        lastOkT_ = t;
        if (!options_.filterEnabled)
            f.filtered = *f.estimate.pose;
        else if (options_.filterKind == FilterKind::OneEuro)
            f.filtered = oneEuro_.update(*f.estimate.pose, t);
        else
            f.filtered = filter_.update(*f.estimate.pose, t, &f.estimate.covariance);
    } else {
        // Never smooth across a loss: the next ok pose starts afresh.
        filter_.reset();
        oneEuro_.reset();
    }
    f.filterMs = msSince(t0);
    return f;
}

TrackedFrame Tracker::markLost(double t, const std::string& reason) {
    TrackedFrame f;
    f.t = t;
    f.estimate.state = TrackingState::Lost;
    f.estimate.reason = reason;
    filter_.reset();
    oneEuro_.reset();
    return f;
}

}  // namespace mirage::tracking
