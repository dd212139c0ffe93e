#include "tracking/Tracker.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "core/math/Pose.h"
#include "tracking/TagFamily.h"

namespace mirage::tracking {
namespace {
double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The step d = (world-frame rotation vector, radians; camera-centre offset, metres) that takes
// pose a to pose b (the pose estimator's perturbation convention).
std::array<double, 6> poseDifference(const Pose& a, const Pose& b) {
    const glm::dvec3 w = rotationVector(b.rotation * glm::inverse(a.rotation));
    const glm::dvec3 c = b.translation - a.translation;
    return {w.x, w.y, w.z, c.x, c.y, c.z};
}

// Pose p moved by the fraction `weight` of the step d (poseDifference).
Pose applyPoseDifference(const Pose& p, const std::array<double, 6>& d, double weight) {
    const glm::dvec3 w = weight * glm::dvec3(d[0], d[1], d[2]);
    const double a = glm::length(w);
    Pose q = p;
    if (a > 0) q.rotation = glm::normalize(glm::angleAxis(a, w / a) * p.rotation);
    q.translation += weight * glm::dvec3(d[3], d[4], d[5]);
    return q;
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

// Side (px) of the blocks texturedRegion judges; the region is a union of whole blocks.
constexpr int kTextureBlockPx = 8;

cv::Rect texturedRegion(const cv::Mat& grey) {
    constexpr int block = kTextureBlockPx;
    const int bw = grey.cols / block, bh = grey.rows / block;
    if (grey.empty() || grey.type() != CV_8UC1 || bw < 1 || bh < 1) return {};
    // Per block: the intensity range over every second pixel of every second row (a tag's
    // border cell is at least 2 px wide wherever libapriltag can find the tag).
    std::vector<uint8_t> lo(size_t(bw * bh), 255), hi(size_t(bw * bh), 0);
    for (int y = 0; y < bh * block; y += 2) {
        const uint8_t* row = grey.ptr<uint8_t>(y);
        uint8_t* l = lo.data() + size_t((y / block) * bw);
        uint8_t* h = hi.data() + size_t((y / block) * bw);
        for (int bx = 0; bx < bw; ++bx) {
            const uint8_t* p = row + bx * block;
            uint8_t a = std::min(std::min(p[0], p[2]), std::min(p[4], p[6]));
            uint8_t b = std::max(std::max(p[0], p[2]), std::max(p[4], p[6]));
            l[bx] = std::min(l[bx], a);
            h[bx] = std::max(h[bx], b);
        }
    }
    std::array<int, 256> hist{};
    for (size_t i = 0; i < lo.size(); ++i) ++hist[size_t(hi[i] - lo[i])];
    // 99th percentile of the block ranges: the tags' black-on-white contrast (robust to a few
    // specular blocks), whatever the exposure.
    int p99 = 255;
    for (int acc = 0, r = 255; r >= 0; --r) {
        acc += hist[size_t(r)];
        if (100 * acc >= int(lo.size())) {
            p99 = r;
            break;
        }
    }
    const int threshold = std::max(12, p99 / 2);
    int x0 = bw, y0 = bh, x1 = -1, y1 = -1;
    for (int by = 0; by < bh; ++by)
        for (int bx = 0; bx < bw; ++bx) {
            const size_t i = size_t(by * bw + bx);
            if (hi[i] - lo[i] < threshold) continue;
            x0 = std::min(x0, bx);
            y0 = std::min(y0, by);
            x1 = std::max(x1, bx);
            y1 = std::max(y1, by);
        }
    if (x1 < 0) return {};
    return cv::Rect(x0 * block, y0 * block, (x1 - x0 + 1) * block, (y1 - y0 + 1) * block);
}

double tagEdgeWidthPx(const cv::Mat& grey, const std::array<glm::dvec2, 4>& corners) {
    double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
    for (const auto& c : corners) {
        x0 = std::min(x0, c.x);
        y0 = std::min(y0, c.y);
        x1 = std::max(x1, c.x);
        y1 = std::max(y1, c.y);
    }
    const cv::Rect box = cv::Rect(cv::Point(int(std::floor(x0)) - 2, int(std::floor(y0)) - 2),
                                  cv::Point(int(std::ceil(x1)) + 3, int(std::ceil(y1)) + 3)) &
                         cv::Rect(0, 0, grey.cols, grey.rows);
    if (box.width < 4 || box.height < 4) return -1;
    const double s = imageSharpness(grey(box));
    return s > 0 ? 1.0 / s : -1;
}

void Tracker::measureBlur(const cv::Mat& grey, std::vector<TagDetection>& dets) const {
    // Motion blur is mostly common to the frame: measured once, on the largest board tag (the
    // most edge pixels), and given to every board tag not measured yet.
    TagDetection* largest = nullptr;
    double largestSide = 0;
    for (auto& d : dets) {
        if (!estimator_.board().find(d.id)) continue;
        const double side = glm::length(d.corners[0] - d.corners[2]);
        if (side > largestSide) {
            largestSide = side;
            largest = &d;
        }
    }
    if (!largest) return;
    const double w =
        largest->edgeWidthPx >= 0 ? largest->edgeWidthPx : tagEdgeWidthPx(grey, largest->corners);
    for (auto& d : dets)
        if (d.edgeWidthPx < 0 && estimator_.board().find(d.id)) d.edgeWidthPx = w;
}

namespace {
// The detector looks for the board's tag family: a board of tag25h9 tags is searched for
// tag25h9 codes, whatever the options' default says.
TrackerOptions forBoard(TrackerOptions o, const Board& board) {
    o.detector.family = board.family;
    return o;
}
}  // namespace

Tracker::Tracker(Board board, CameraIntrinsics camera, TrackerOptions options)
    : options_(forBoard(options, board)),
      detector_(options_.detector),
      tagFinder_(board, camera, options.prediction),
      estimator_(std::move(board), std::move(camera), options.pose),
      filter_(options.filter),
      oneEuro_(options.oneEuro) {
    if (options_.features.enabled)
        features_ = std::make_unique<FeatureTracker>(estimator_.board(), estimator_.camera(),
                                                     options_.features, options_.pose);
    coarseCellsAtBorder_ = TagFamily(options_.detector.family).widthAtBorder();
    double diameter = 0, largest = 0;
    const auto& tags = estimator_.board().tags;
    for (size_t i = 0; i < tags.size(); ++i) {
        largest = std::max(largest, tags[i].size);
        const auto ci = tags[i].cornersInWorld();
        for (size_t j = i; j < tags.size(); ++j) {
            const auto cj = tags[j].cornersInWorld();
            for (const auto& a : ci)
                for (const auto& b : cj) diameter = std::max(diameter, glm::length(a - b));
        }
    }
    largestTagOverDiameter_ = diameter > 0 ? largest / diameter : 0;
}

glm::dvec3 Tracker::boardVelocity() const {
    if (boardCentres_.size() < 2) return glm::dvec3(0.0);
    const double span = boardCentres_.back().first - boardCentres_.front().first;
    return (boardCentres_.back().second - boardCentres_.front().second) / span;
}

Pose Tracker::predictPose(double t) const {
    Pose p = *lastOk_;
    const double span = lastOkT_ - previousOkT_;
    if (!previousOk_ || !(span > 0) || span > options_.priorMaxAgeS) return p;
    const double s = (t - lastOkT_) / span;
    // Constant velocity in the camera's own frame: the motion from the previous to the last pose
    // (delta = T_prev^-1 T_last), scaled by s, applied again after the last pose. An orbit or a
    // turn at a constant rate is predicted exactly (a constant world-frame velocity would cut the
    // arc's chord: ~7 px at 640x480 in the benchmark's orbit, 6 degrees per frame).
    const glm::dquat dq = glm::inverse(previousOk_->rotation) * lastOk_->rotation;
    const glm::dvec3 dt =
        glm::inverse(previousOk_->rotation) * (lastOk_->translation - previousOk_->translation);
    const double w = std::clamp(std::abs(dq.w), 0.0, 1.0);
    const double angle = 2.0 * std::acos(w);
    glm::dquat step(1.0, 0.0, 0.0, 0.0);
    if (angle > 1e-12) {
        const glm::dvec3 axis =
            glm::normalize(glm::dvec3(dq.x, dq.y, dq.z) * (dq.w < 0 ? -1.0 : 1.0));
        step = glm::angleAxis(angle * s, axis);
    }
    p.rotation = glm::normalize(lastOk_->rotation * step);
    p.translation = lastOk_->translation + lastOk_->rotation * (s * dt);
    return p;
}

std::optional<cv::Rect> Tracker::boardRegion(const Pose& T_world_camera, cv::Size image,
                                             bool withMargins) const {
    const Pose T_camera_world = T_world_camera.inverse();
    double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
    for (const auto& tag : estimator_.board().tags) {
        for (const auto& c : tag.cornersInWorld()) {
            const glm::dvec3 Xc = T_camera_world * c;
            if (!(Xc.z > 1e-3)) return std::nullopt;  // the board reaches behind the camera
            const auto px = estimator_.camera().project(Xc);
            if (!px) return std::nullopt;
            x0 = std::min(x0, px->x);
            y0 = std::min(y0, px->y);
            x1 = std::max(x1, px->x);
            y1 = std::max(y1, px->y);
        }
    }
    const double mx =
        withMargins ? options_.roiMarginPx + options_.roiMarginFraction * (x1 - x0) : 0.0;
    const double my =
        withMargins ? options_.roiMarginPx + options_.roiMarginFraction * (y1 - y0) : 0.0;
    // Origin aligned down to 8 pixels (libapriltag's decimation and threshold tiles).
    const int bx0 = std::max(0, int(std::floor(x0 - mx)) / 8 * 8);
    const int by0 = std::max(0, int(std::floor(y0 - my)) / 8 * 8);
    const int bx1 = std::min(image.width, int(std::ceil(x1 + mx)));
    const int by1 = std::min(image.height, int(std::ceil(y1 + my)));
    if (bx1 <= bx0 || by1 <= by0) return cv::Rect();
    return cv::Rect(bx0, by0, bx1 - bx0, by1 - by0);
}

bool Tracker::coarseToFine(const cv::Mat& grey, const cv::Rect& region, float decimate,
                           const std::optional<Pose>& prior, TrackedFrame& f) {
    f.coarseTried = true;
    Detector* coarseDetector = nullptr;
    for (auto& [d, det] : coarseDetectors_)
        if (d == decimate) coarseDetector = det.get();
    if (!coarseDetector) {
        DetectorOptions o = options_.detector;
        o.decimate = decimate;
        // Small tags are the ordinary search's job (the fallback).
        o.fullResolutionRetry = false;
        // Refined by coarseToFine, in one or two passes.
        o.refineCorners = false;
        // At full resolution the ordinary search's edge refinement: its quads are then as
        // precise as the ordinary search's full-resolution ones, for the pose and the finder.
        o.refineEdges =
            decimate > 1.0f ? options_.coarseRefineEdges : options_.detector.refineEdges;
        coarseDetectors_.emplace_back(decimate, std::make_unique<Detector>(o));
        coarseDetector = coarseDetectors_.back().second.get();
    }
    f.coarseWindow = region & cv::Rect(0, 0, grey.cols, grey.rows);
    auto t0 = std::chrono::steady_clock::now();
    std::vector<TagDetection> coarse = coarseDetector->detect(grey, region);
    f.coarseTags = int(coarse.size());
    // Only tags whose corners mirage's refinement can measure at full resolution are used
    // (libapriltag's corners on the decimated image are off by up to ~1 px with its edge
    // refinement, up to the decimation factor without); the finder tries the others.
    const double startErrorPx = coarseDetector->options().refineEdges ? 1.5 : double(decimate);
    std::erase_if(coarse, [&](TagDetection& d) {
        d.refined =
            Detector::refineQuadCorners(grey, coarseCellsAtBorder_, d.corners, startErrorPx);
        return !d.refined;
    });
    f.detectMs += msSince(t0);
    if (coarse.empty()) return false;
    t0 = std::chrono::steady_clock::now();
    // The coarse pose from the largest tags only: the estimator's cost grows with the tags, and
    // the finder's image correction takes up what a pose from few tags leaves.
    std::vector<TagDetection> largest = coarse;
    auto side = [](const TagDetection& d) {
        double s = 1e18;
        for (int k = 0; k < 4; ++k)
            s = std::min(s, glm::length(d.corners[size_t(k)] - d.corners[size_t((k + 1) % 4)]));
        return s;
    };
    std::sort(largest.begin(), largest.end(),
              [&](const TagDetection& a, const TagDetection& b) { return side(a) > side(b); });
    if (options_.coarsePoseTags > 0 && int(largest.size()) > options_.coarsePoseTags)
        largest.resize(size_t(options_.coarsePoseTags));
    measureBlur(grey, largest);
    const PoseEstimate ce = estimator_.estimate(largest, prior);
    f.poseMs += msSince(t0);
    // Not ok (one tag with an undecided planar flip, outliers, ...): the ordinary search decides.
    // An uncertain pose (settled, but too uncertain to report) still predicts where the other
    // tags are; the pose from all of them is judged again.
    if (ce.state != TrackingState::Ok && ce.state != TrackingState::Uncertain) return false;

    t0 = std::chrono::steady_clock::now();
    PredictedTagStats stats;
    std::vector<TagDetection> dets =
        tagFinder_.find(grey, *ce.pose, options_.coarseSearchPx, coarse, &stats);
    // libapriltag's tags the finder did not predict (too small or too close to the image edge
    // for it; each was decoded by libapriltag) join the others.
    for (const auto& c : coarse) {
        bool have = false;
        for (const auto& d : dets) have = have || d.id == c.id;
        if (!have) dets.push_back(c);
    }
    f.detectMs += msSince(t0);
    const int need = std::max(options_.trackMinTags,
                              int(std::ceil(options_.trackMinFraction * double(stats.predicted))));
    if (!f.tagTrackingTried) f.prediction = stats;
    if (stats.verified < need) return false;
    t0 = std::chrono::steady_clock::now();
    measureBlur(grey, dets);
    PoseEstimate e = estimator_.estimate(dets, prior, *ce.pose);
    f.poseMs += msSince(t0);
    if (e.state != TrackingState::Ok) return false;
    f.coarseUsed = true;
    f.detections = std::move(dets);
    f.estimate = std::move(e);
    return true;
}

std::vector<float> Tracker::coarseCascade(const SearchPlan& plan) const {
    std::vector<float> out;
    if (!options_.coarseFirstCascade || !plan.windowed) return out;
    for (float d : {3.0f, 2.0f, 1.0f})
        if (d < plan.coarseDecimate && (d > 1.0f || options_.fullResolutionFallback))
            out.push_back(d);
    return out;
}

Detector& Tracker::fullResolutionDetector() {
    if (!fullResolutionDetector_) {
        DetectorOptions o = options_.detector;
        o.decimate = 1.0f;
        o.fullResolutionRetry = false;
        o.blurSigma = options_.fullResolutionBlurSigma;
        o.decodeSharpening = options_.fullResolutionSharpening;
        o.refineEdges = options_.fullResolutionRefineEdges;
        fullResolutionDetector_ = std::make_unique<Detector>(o);
    }
    return *fullResolutionDetector_;
}

void Tracker::searchTags(const cv::Mat& grey, const cv::Rect& region, const cv::Rect& retryWindow,
                         const std::optional<Pose>& ambiguityPrior, double t, TrackedFrame& f) {
    f.fullResolutionRegion = cv::Rect();
    f.fullResolutionSought = f.fullResolutionFound = f.fullResolutionFinderFound = 0;
    const DetectorOptions& dopt = options_.detector;
    // The window's search ends with the finder's tags: part of the adaptive full-resolution pass.
    const bool windowFirst = !retryWindow.empty() && options_.fullResolutionFallback &&
                             dopt.fullResolutionRetry && dopt.decimate > 1.0f;
    auto t0 = std::chrono::steady_clock::now();
    f.detections = detector_.detect(grey, region, dopt.decimate, !windowFirst);
    f.detectMs += msSince(t0);
    if (windowFirst && f.detections.empty()) {
        // The window's tags at full resolution and the finder for the others; else the whole
        // region at full resolution, as the detector's own retry would have searched it.
        f.windowRetried = true;
        if (coarseToFine(grey, retryWindow, 1.0f, ambiguityPrior, f)) return;
        t0 = std::chrono::steady_clock::now();
        f.detections = detector_.detect(grey, region, 1.0f, false);
        f.detectMs += msSince(t0);
    }
    t0 = std::chrono::steady_clock::now();
    measureBlur(grey, f.detections);
    f.estimate = estimator_.estimate(f.detections, ambiguityPrior);
    f.poseMs += msSince(t0);
    // With no tag found the detector has searched the region at full resolution already
    // (DetectorOptions::fullResolutionRetry).
    if (!options_.fullResolutionFallback || !(options_.detector.decimate > 1.0f) ||
        f.detections.empty())
        return;
    const auto settled = [&] {
        return f.estimate.pose && (f.estimate.state == TrackingState::Ok ||
                                   f.estimate.state == TrackingState::Uncertain);
    };
    if (!settled()) {
        // No pose of this frame to say where the missed tags are: where the motion prediction
        // of the recent ok poses puts them (video), else anywhere in the region, searched by
        // libapriltag at full resolution.
        t0 = std::chrono::steady_clock::now();
        cv::Rect again = region & cv::Rect(0, 0, grey.cols, grey.rows);
        if (lastOk_ && t >= lastOkT_ && t - lastOkT_ <= options_.priorMaxAgeS) {
            const MissingTags m =
                findMissingTags(estimator_.board(), estimator_.camera(), predictPose(t),
                                f.detections, options_.missingTags);
            f.fullResolutionSought = int(m.ids.size());
            again = m.region;
        }
        if (!again.empty()) {
            f.fullResolutionRegion = again;
            for (auto& d : fullResolutionDetector().detect(grey, again)) {
                // Board tags the decimated search missed join the frame's (a tag id seen twice
                // would be dropped by the estimator).
                if (!estimator_.board().find(d.id)) continue;
                const bool have = std::any_of(f.detections.begin(), f.detections.end(),
                                              [&](const TagDetection& e) { return e.id == d.id; });
                if (have) continue;
                f.detections.push_back(d);
                ++f.fullResolutionFound;
            }
        }
        f.detectMs += msSince(t0);
        if (f.fullResolutionFound == 0) return;
        t0 = std::chrono::steady_clock::now();
        measureBlur(grey, f.detections);
        f.estimate = estimator_.estimate(f.detections, ambiguityPrior);
        f.poseMs += msSince(t0);
        if (!settled()) return;
    }
    // A settled pose of this frame predicts the missed tags to a few pixels: the tracking mode's
    // finder looks for each where the pose puts them (edges at full resolution, sub-pixel
    // corners, every cell verified against the expected code), corrected by the offsets of the
    // tags found; it follows tags from 12 px, smaller and steeper than libapriltag decodes.
    t0 = std::chrono::steady_clock::now();
    const MissingTags m = findMissingTags(estimator_.board(), estimator_.camera(), *f.estimate.pose,
                                          f.detections, options_.missingTags);
    if (m.ids.empty()) {
        f.detectMs += msSince(t0);
        return;
    }
    const size_t before = f.detections.size();
    std::vector<TagDetection> dets =
        tagFinder_.find(grey, *f.estimate.pose, options_.coarseSearchPx, f.detections);
    // The finder returns the known tags it predicted and the verified others; known tags it did
    // not predict (cut by the image border, too small for it) are kept.
    for (const auto& d : f.detections) {
        const bool have = std::any_of(dets.begin(), dets.end(),
                                      [&](const TagDetection& e) { return e.id == d.id; });
        if (!have) dets.push_back(d);
    }
    f.detectMs += msSince(t0);
    if (dets.size() <= before) return;
    f.fullResolutionFinderFound = int(dets.size() - before);
    f.detections = std::move(dets);
    t0 = std::chrono::steady_clock::now();
    measureBlur(grey, f.detections);
    const Pose initial = *f.estimate.pose;
    f.estimate = estimator_.estimate(f.detections, ambiguityPrior, initial);
    f.poseMs += msSince(t0);
}

TrackedFrame Tracker::process(const cv::Mat& image, double t) {
    TrackedFrame f;
    f.t = t;
    cv::Mat grey;
    if (image.type() == CV_8UC3)
        cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
    else
        grey = image;
    std::optional<Pose> prior;
    if (lastOk_ && t - lastOkT_ <= options_.priorMaxAgeS && t >= lastOkT_) prior = lastOk_;
    // Only a well-determined previous pose may decide the planar ambiguity.
    const std::optional<Pose> ambiguityPrior = lastOkWellDetermined_ ? prior : std::nullopt;
    f.searchRegion = cv::Rect(0, 0, grey.cols, grey.rows);
    // The previous pose may guide this frame unless a full search is due.
    const bool usePrior = prior && ++framesSinceFullSearch_ < options_.fullFrameEvery;

    if (features_) {
        std::optional<Pose> predicted;
        if (lastOk_ && t >= lastOkT_ && t - lastOkT_ <= options_.features.maxGapS)
            predicted = predictPose(t);
        features_->track(grey, predicted);
        f.featureMs = features_->stats().trackMs;
    }
    if (options_.tagTracking && usePrior) trackPredictedTags(grey, t, ambiguityPrior, f);
    if (!f.tagTracked) {
        const SearchPlan plan = planSearch(grey, prior, usePrior, f);
        searchPlanned(grey, plan, ambiguityPrior, t, f);
    }
    classifyNoTags(grey, f);
    extendWithFeatures(grey, t, f);
    guardPrediction(t, prior, f);
    record(t, f);
    return f;
}

void Tracker::trackPredictedTags(const cv::Mat& grey, double t,
                                 const std::optional<Pose>& ambiguityPrior, TrackedFrame& f) {
    // Tracking mode: the tags where the predicted pose puts them, verified.
    auto t0 = std::chrono::steady_clock::now();
    f.tagTrackingTried = true;
    const Pose predicted = predictPose(t);
    f.predictedPose = predicted;
    auto dets = tagFinder_.find(grey, predicted, *lastOk_, &f.prediction);
    const int need =
        std::max(options_.trackMinTags,
                 int(std::ceil(options_.trackMinFraction * double(f.prediction.predicted))));
    f.detectMs = msSince(t0);
    if (f.prediction.verified < need) return;
    t0 = std::chrono::steady_clock::now();
    measureBlur(grey, dets);
    PoseEstimate e = estimator_.estimate(dets, ambiguityPrior, predicted);
    f.poseMs = msSince(t0);
    if (e.state != TrackingState::Ok) return;
    f.tagTracked = true;
    f.detections = std::move(dets);
    f.estimate = std::move(e);
    f.searchRegion = cv::Rect();
}

Tracker::SearchPlan Tracker::planSearch(const cv::Mat& grey, const std::optional<Pose>& prior,
                                        bool usePrior, TrackedFrame& f) {
    const cv::Rect full(0, 0, grey.cols, grey.rows);
    if (options_.roiEnabled && usePrior) {
        const auto r = boardRegion(*prior, grey.size(), true);
        // Not worth it when the box covers most of the image.
        if (r && r->area() > 0 && r->area() < 0.7 * full.area()) f.searchRegion = *r;
    }
    if (f.searchRegion == full) framesSinceFullSearch_ = 0;
    // No pose to say where the board is: where the image has the tags' contrast.
    const cv::Rect r = !prior && (options_.textureRegion || options_.coarseFirst)
                           ? texturedRegion(grey)
                           : cv::Rect();
    const double m = options_.textureMarginPx;
    const cv::Rect grown =
        cv::Rect(cv::Point(std::max(0, int(r.x - m)) / kTextureBlockPx * kTextureBlockPx,
                           std::max(0, int(r.y - m)) / kTextureBlockPx * kTextureBlockPx),
                 cv::Point(int(r.br().x + m), int(r.br().y + m))) &
        full;
    if (options_.textureRegion && !prior) {
        if (r.area() > 0 && grown.area() <= options_.textureMaxFraction * full.area()) {
            f.searchRegion = grown;
            f.textureRegionUsed = true;
        }
    }

    SearchPlan plan;
    plan.coarseRegion = f.searchRegion == full || f.textureRegionUsed;
    plan.coarseDecimate = options_.coarseToFine && grey.cols >= options_.coarseMinWidth
                              ? options_.coarseDecimate
                              : 0.0f;
    if (options_.coarseFirst && r.area() > 0) {
        // The tags' size from the textured region picks the decimation (or none).
        f.coarseFirstSidePx =
            largestTagOverDiameter_ * std::hypot(double(r.width), double(r.height));
        plan.coarseDecimate = 0;
        for (float d : options_.coarseFirstDecimations)
            if (d > plan.coarseDecimate && f.coarseFirstSidePx >= d * options_.coarseFirstMinSidePx)
                plan.coarseDecimate = d;
        f.coarseFirstDecimate = plan.coarseDecimate;
    }
    // The coarse search reads only the textured region also when it is too large for the
    // ordinary search (a near board): a confirmed coarse pose has every board tag predicted
    // in the whole image searched by the finder, and an unconfirmed one falls back to the
    // ordinary search of f.searchRegion.
    plan.coarseSearch = f.searchRegion;
    if (options_.coarseFirst && options_.textureRegion && r.area() > 0) {
        plan.coarseSearch = grown;
        if (options_.coarseWindowFraction > 0 && options_.coarseWindowFraction < 1) {
            // The window about the region's centre, origin aligned like the region's.
            const double hw = 0.5 * options_.coarseWindowFraction * r.width + m;
            const double hh = 0.5 * options_.coarseWindowFraction * r.height + m;
            const double cx = r.x + 0.5 * r.width, cy = r.y + 0.5 * r.height;
            plan.coarseSearch =
                cv::Rect(cv::Point(std::max(0, int(cx - hw)) / kTextureBlockPx * kTextureBlockPx,
                                   std::max(0, int(cy - hh)) / kTextureBlockPx * kTextureBlockPx),
                         cv::Point(int(cx + hw), int(cy + hh))) &
                full;
        }
        // The finer searches of the window only where the textured region stands for the board
        // (it was small enough to be searched alone): where texture fills the view, the window
        // is merely the image's centre, and a frame without the board would pay for them.
        plan.windowed = f.textureRegionUsed;
        if (options_.windowRetry && f.textureRegionUsed && plan.coarseSearch != grown)
            plan.retryWindow = plan.coarseSearch;
    }
    return plan;
}

void Tracker::searchPlanned(const cv::Mat& grey, const SearchPlan& plan,
                            const std::optional<Pose>& ambiguityPrior, double t, TrackedFrame& f) {
    const cv::Rect full(0, 0, grey.cols, grey.rows);
    auto detectAndEstimate = [&](const cv::Rect& region, const cv::Rect& retryWindow) {
        searchTags(grey, region, retryWindow, ambiguityPrior, t, f);
    };
    // Decimation 1 is a coarse stage too (coarseFirstDecimations): libapriltag at full
    // resolution in the window.
    bool done = false;
    // The window already searched at full resolution needs no window retry.
    cv::Rect retryWindow = plan.retryWindow;
    if (plan.coarseDecimate >= 1.0f && plan.coarseRegion) {
        done = coarseToFine(grey, plan.coarseSearch, plan.coarseDecimate, ambiguityPrior, f);
        float searched = plan.coarseDecimate;
        // No tag in the window at that decimation (the side estimate is an overestimate under
        // foreshortening): the next finer decimation in the same window.
        for (float d : coarseCascade(plan)) {
            if (done || f.coarseTags > 0) break;
            f.coarseCascaded = true;
            searched = d;
            done = coarseToFine(grey, plan.coarseSearch, d, ambiguityPrior, f);
        }
        if (searched == 1.0f && plan.coarseSearch == plan.retryWindow) retryWindow = cv::Rect();
    }
    if (!done) detectAndEstimate(f.searchRegion, retryWindow);
    bool retry = f.searchRegion != full && f.estimate.state != TrackingState::Ok;
    if (f.searchRegion != full && f.estimate.state == TrackingState::Ok) {
        const auto now = boardRegion(*f.estimate.pose, grey.size(), false);
        retry = !now || (*now & f.searchRegion) != *now;
    }
    if (f.textureRegionUsed && f.estimate.pose) {
        // The textured region holds the whole board under the frame's pose (ok or not):
        // searching the rest of the image cannot add a tag of that board. Else the region
        // may have cut off tags: search the whole image.
        const auto now = boardRegion(*f.estimate.pose, grey.size(), false);
        retry = !now || (*now & f.searchRegion) != *now;
    }
    if (retry) {
        // The region missed the board or part of it (fast motion, occlusion): search the
        // whole image before giving up or using fewer tags than the frame shows.
        f.fullFrameRetry = true;
        framesSinceFullSearch_ = 0;
        detectAndEstimate(full, cv::Rect());
    }
}

void Tracker::classifyNoTags(const cv::Mat& grey, TrackedFrame& f) const {
    if (f.estimate.state != TrackingState::NoTags) return;
    const auto t0 = std::chrono::steady_clock::now();
    f.sharpness = imageSharpness(grey);
    if (f.sharpness > 0 && f.sharpness < options_.minSharpness) {
        f.estimate.state = TrackingState::TooBlurred;
        char buf[160];
        std::snprintf(buf, sizeof buf,
                      "no tag found and the image is blurred (sharpness %.3f < %.3f)", f.sharpness,
                      options_.minSharpness);
        f.estimate.reason = buf;
    }
    f.poseMs += msSince(t0);
}

void Tracker::extendWithFeatures(const cv::Mat& grey, double t, TrackedFrame& f) {
    f.mode = TrackingMode::Board;
    if (!features_) return;
    const auto t0 = std::chrono::steady_clock::now();
    auto boardBox = [&](const Pose& T) {
        const auto r = boardRegion(T, grey.size(), false);
        return r ? *r : cv::Rect();
    };
    if (f.estimate.state == TrackingState::Ok) {
        // Back on the board after poses from the features: how far the landmarks had drifted
        // from it is blended out over the next frames instead of jumping.
        reanchorLeft_ = 0;
        if (lastMode_ != TrackingMode::Board && options_.reanchorFrames > 0 && lastOk_ &&
            t - lastOkT_ <= options_.features.maxGapS) {
            const PoseEstimate drifted =
                features_->estimate(predictPose(t), {}, t - lastOkT_, boardVelocity());
            if (drifted.state == TrackingState::Ok) {
                reanchorOffset_ = poseDifference(*f.estimate.pose, *drifted.pose);
                reanchorLeft_ = options_.reanchorFrames;
            }
        }
        features_->learn(grey, f.estimate, true, boardBox(*f.estimate.pose));
    } else if (lastOk_ && t >= lastOkT_ && t - lastOkT_ <= options_.features.maxGapS) {
        PoseEstimate e =
            features_->estimate(predictPose(t), f.detections, t - lastOkT_, boardVelocity());
        if (e.state == TrackingState::Ok) {
            f.mode =
                e.tagsUsed.empty() ? TrackingMode::FeaturesOnly : TrackingMode::BoardAndFeatures;
            f.estimate = std::move(e);
            features_->learn(grey, f.estimate, false, boardBox(*f.estimate.pose));
        } else if (!e.reason.empty()) {
            f.estimate.reason += (f.estimate.reason.empty() ? "" : "; ") + e.reason;
        }
    } else {
        features_->reset();
    }
    f.features = features_->stats();
    f.featureMs += msSince(t0);
}

void Tracker::guardPrediction(double t, const std::optional<Pose>& prior, TrackedFrame& f) const {
    // A pose from the features is always checked against the motion; one from tags when it is
    // not well determined.
    if (f.estimate.state != TrackingState::Ok || !prior) return;
    if (f.mode == TrackingMode::Board &&
        f.estimate.wellDetermined(options_.priorMinTags, options_.priorMaxSigmaRotDeg))
        return;
    // Prediction guard: a weak fit far from where the recent motion puts the camera.
    const Pose predicted = f.predictedPose ? *f.predictedPose : predictPose(t);
    const double rotDeg =
        glm::degrees(rotationAngleBetween(predicted.rotation, f.estimate.pose->rotation));
    const double pos = glm::length(predicted.translation - f.estimate.pose->translation);
    const double dist = std::max(1e-6, f.estimate.distanceM);
    if (rotDeg > options_.guardMaxRotDeg || pos > options_.guardMaxPosFraction * dist) {
        f.estimate.state = TrackingState::Uncertain;
        char buf[200];
        std::snprintf(buf, sizeof buf,
                      "; %.1f deg / %.1f %% of the distance from the motion prediction with "
                      "a weak fit (bounds %.1f deg / %.1f %%)",
                      rotDeg, 100 * pos / dist, options_.guardMaxRotDeg,
                      100 * options_.guardMaxPosFraction);
        f.estimate.reason += buf;
    }
}

void Tracker::record(double t, TrackedFrame& f) {
    const auto t0 = std::chrono::steady_clock::now();
    if (f.estimate.state == TrackingState::Ok) {
        lastOkWellDetermined_ =
            f.mode == TrackingMode::Board &&
            f.estimate.wellDetermined(options_.priorMinTags, options_.priorMaxSigmaRotDeg);
        previousOk_ = lastOk_;
        previousOkT_ = lastOkT_;
        lastOk_ = f.estimate.pose;
        lastOkT_ = t;
        lastMode_ = f.mode;
        if (f.mode == TrackingMode::Board) {
            if (!boardCentres_.empty() && !(t > boardCentres_.back().first)) boardCentres_.clear();
            boardCentres_.emplace_back(t, f.estimate.pose->translation);
            while (t - boardCentres_.front().first > kBoardVelocityWindowS)
                boardCentres_.pop_front();
        }
        if (!options_.filterEnabled)
            f.filtered = *f.estimate.pose;
        else if (options_.filterKind == FilterKind::OneEuro)
            f.filtered = oneEuro_.update(*f.estimate.pose, t);
        else
            f.filtered = filter_.update(*f.estimate.pose, t, &f.estimate.covariance);
        if (reanchorLeft_ > 0 && f.mode == TrackingMode::Board) {
            // The reported pose approaches the board's in reanchorFrames equal steps.
            f.reanchorWeight = double(reanchorLeft_) / double(options_.reanchorFrames + 1);
            f.filtered = applyPoseDifference(*f.filtered, reanchorOffset_, f.reanchorWeight);
            --reanchorLeft_;
        }
    } else {
        // Never smooth across a loss: the next ok pose starts afresh.
        filter_.reset();
        oneEuro_.reset();
        reanchorLeft_ = 0;
    }
    f.filterMs = msSince(t0);
}

TrackedFrame Tracker::markLost(double t, const std::string& reason) {
    TrackedFrame f;
    f.t = t;
    f.estimate.state = TrackingState::Lost;
    f.estimate.reason = reason;
    filter_.reset();
    oneEuro_.reset();
    reanchorLeft_ = 0;
    // The next frame's features cannot be followed from the last readable one.
    if (features_) features_->reset();
    return f;
}

}  // namespace mirage::tracking
