#include "tracking/Detector.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <apriltag/apriltag.h>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/image/ImageIO.h"
#include "tracking/ImageLine.h"
#include "tracking/TagFamily.h"

namespace mirage::tracking {

namespace {

// sRGB-encoded 8-bit level -> linear light (camera frames are sRGB-encoded, docs/tracking.md).
const std::array<float, 256>& linearLut() {
    static const std::array<float, 256> lut = [] {
        std::array<float, 256> l{};
        for (int i = 0; i < 256; ++i) l[size_t(i)] = srgbToLinear(float(i) / 255.0f);
        return l;
    }();
    return lut;
}

// Bilinear linear-light intensity at (x, y) in OpenCV pixel coordinates; false outside.
bool sampleLinear(const cv::Mat& grey, double x, double y, double& v) {
    const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
    if (x0 < 0 || y0 < 0 || x0 + 1 >= grey.cols || y0 + 1 >= grey.rows) return false;
    const double fx = x - x0, fy = y - y0;
    const auto& lut = linearLut();
    const uint8_t* r0 = grey.ptr<uint8_t>(y0);
    const uint8_t* r1 = grey.ptr<uint8_t>(y0 + 1);
    v = (1 - fy) * ((1 - fx) * lut[r0[x0]] + fx * lut[r0[x0 + 1]]) +
        fy * ((1 - fx) * lut[r1[x0]] + fx * lut[r1[x0 + 1]]);
    return true;
}

// Whether sampleLinear can sample at p (its 2x2 neighbourhood lies in the image).
bool insideForBilinear(const cv::Mat& grey, const glm::dvec2& p) {
    return p.x >= 0 && p.y >= 0 && p.x < grey.cols - 1 && p.y < grey.rows - 1;
}

}  // namespace

// Sub-pixel edge refinement (see DetectorOptions::refineCorners). Leaves the corners unchanged if
// any edge cannot be measured or a corner would move by more than maxMovePx.
bool Detector::refineCorners(const cv::Mat& grey, int cellsAtBorder,
                             std::array<glm::dvec2, 4>& corners, double maxMovePx) {
    glm::dvec2 centroid(0.0);
    for (const auto& c : corners) centroid += 0.25 * c;
    std::array<ImageLine, 4> lines;
    for (int k = 0; k < 4; ++k) {
        const glm::dvec2 a = corners[size_t(k)], b = corners[size_t((k + 1) % 4)];
        const double len = glm::length(b - a);
        if (len < 4.0) return false;
        const glm::dvec2 dir = (b - a) / len;
        glm::dvec2 normal(-dir.y, dir.x);
        if (glm::dot(normal, 0.5 * (a + b) - centroid) < 0) normal = -normal;  // points outward
        // Search +-range across the edge: within the black border cell inside and the white
        // quiet-zone cell outside.
        // Cell size across this edge: the tag's extent along the normal (to the opposite edge)
        // over the cells at the border. Under foreshortening it is smaller than along the edge,
        // and a profile longer than one cell would reach the data bits and bias the levels.
        const glm::dvec2 oppositeMid =
            0.5 * (corners[size_t((k + 2) % 4)] + corners[size_t((k + 3) % 4)]);
        const double cell = std::abs(glm::dot(normal, 0.5 * (a + b) - oppositeMid)) / cellsAtBorder;
        const double range = std::clamp(0.45 * cell, 0.75, 4.0);
        const double step = 0.25;
        const int nProfile = int(2 * range / step) + 1;
        const int nSamples = std::clamp(int(len / 2), 6, 40);
        std::vector<glm::dvec2> pts;
        std::vector<double> weights;
        // Samples of a profile are taken lazily (NaN = not sampled yet): the levels at both ends,
        // then the segments in order of their distance from the initial edge until no segment
        // can hold a crossing closer than the one found. The result is the crossing closest to
        // the profile centre, as if every sample had been taken (large tags have profiles of up
        // to 33 samples, of which ~4-8 are needed).
        std::vector<double> profile(static_cast<size_t>(nProfile));
        const double tLast = -range + (nProfile - 1) * step;
        // Segment holding t = 0 (the initial edge), clamped to the profile.
        const int centreSeg = std::clamp(int(std::floor(range / step)), 0, nProfile - 2);
        for (int s = 0; s < nSamples; ++s) {
            const double f = 0.15 + 0.7 * (s + 0.5) / nSamples;
            const glm::dvec2 base = a + f * (b - a);
            // The bilinear sampling domain is convex: both ends inside = every sample inside.
            const glm::dvec2 pFirst = base - normal * range, pLast = base + normal * tLast;
            if (!insideForBilinear(grey, pFirst) || !insideForBilinear(grey, pLast)) continue;
            std::fill(profile.begin(), profile.end(), std::numeric_limits<double>::quiet_NaN());
            auto at = [&](int i) {
                double& v = profile[size_t(i)];
                if (std::isnan(v)) {
                    const glm::dvec2 p = base + normal * (-range + i * step);
                    sampleLinear(grey, p.x, p.y, v);
                }
                return v;
            };
            const double dark = 0.5 * (at(0) + at(1));
            const double bright = 0.5 * (at(nProfile - 1) + at(nProfile - 2));
            const double contrast = bright - dark;
            if (contrast < 0.03) continue;
            const double mid = 0.5 * (dark + bright);
            // Crossing of the mid level closest to the initial edge (profile centre).
            double best = 1e9, bestT = 0;
            auto trySegment = [&](int i) {
                const double v0 = at(i), v1 = at(i + 1);
                if ((v0 - mid) * (v1 - mid) > 0 || v0 == v1) return;
                const double tc = -range + step * (i + (mid - v0) / (v1 - v0));
                if (std::abs(tc) < std::abs(best)) {
                    best = tc;
                    bestT = tc;
                }
            };
            trySegment(centreSeg);
            // Distance from t = 0 to the nearest point of the segments left and right of those
            // tried so far.
            int left = centreSeg - 1, right = centreSeg + 1;
            while (left >= 0 || right + 1 < nProfile) {
                const double dl = left >= 0 ? std::abs(-range + (left + 1) * step) : 1e18;
                const double dr = right + 1 < nProfile ? std::abs(-range + right * step) : 1e18;
                if (std::min(dl, dr) > std::abs(best)) break;
                if (dl <= dr)
                    trySegment(left--);
                else
                    trySegment(right++);
            }
            if (best > 1e8) continue;
            pts.push_back(base + normal * bestT);
            weights.push_back(contrast);
        }
        // Most samples must have found the edge (a clean black-to-white step), else the border is
        // occluded, damaged or next to dark surroundings: keep libapriltag's corners.
        if (pts.size() < 4 || 5 * pts.size() < 3 * size_t(nSamples)) return false;
        // Weighted total-least-squares line through the edge points.
        double wsum = 0;
        glm::dvec2 mean(0.0);
        for (size_t i = 0; i < pts.size(); ++i) {
            mean += weights[i] * pts[i];
            wsum += weights[i];
        }
        mean /= wsum;
        double sxx = 0, sxy = 0, syy = 0;
        for (size_t i = 0; i < pts.size(); ++i) {
            const glm::dvec2 d = pts[i] - mean;
            sxx += weights[i] * d.x * d.x;
            sxy += weights[i] * d.x * d.y;
            syy += weights[i] * d.y * d.y;
        }
        const double angle = 0.5 * std::atan2(2 * sxy, sxx - syy);
        lines[size_t(k)] = {mean, {std::cos(angle), std::sin(angle)}};
        // The edge points must lie on a line (RMS distance under 0.3 px): a curved or broken
        // edge (lens blur across a fold, a partial occluder) is not refined.
        const glm::dvec2 n(-std::sin(angle), std::cos(angle));
        double res = 0;
        for (size_t i = 0; i < pts.size(); ++i) {
            const double dist = glm::dot(pts[i] - mean, n);
            res += weights[i] * dist * dist;
        }
        if (std::sqrt(res / wsum) > 0.3) return false;
    }
    std::array<glm::dvec2, 4> refined;
    for (int k = 0; k < 4; ++k) {
        // Corner k joins edge k-1 (corner k-1 -> k) and edge k (corner k -> k+1).
        if (!intersect(lines[size_t((k + 3) % 4)], lines[size_t(k)], refined[size_t(k)]))
            return false;
        if (glm::length(refined[size_t(k)] - corners[size_t(k)]) > maxMovePx) return false;
    }
    corners = refined;
    return true;
}

bool Detector::refineQuadCorners(const cv::Mat& grey, int cellsAtBorder,
                                 std::array<glm::dvec2, 4>& corners, double startErrorPx) {
    std::array<glm::dvec2, 4> refined = corners;
    if (!refineCorners(grey, cellsAtBorder, refined, std::max(1.5, startErrorPx))) return false;
    double moved = 0;
    for (size_t k = 0; k < 4; ++k) moved = std::max(moved, glm::length(refined[k] - corners[k]));
    if (moved > kSecondPassMovePx && !refineCorners(grey, cellsAtBorder, refined)) return false;
    corners = refined;
    return true;
}

Detector::Detector(const DetectorOptions& options)
    : options_(options), family_(std::make_unique<TagFamily>(options.family)) {
    if (!(options.decimate >= 1.0f)) throw Error("detector: decimate must be >= 1");
    if (!(options.blurSigma >= 0.0f)) throw Error("detector: blur sigma must be >= 0");
    if (options.threads < 1) throw Error("detector: threads must be >= 1");
    if (options.maxHammingCorrected < 0 || options.maxHammingCorrected > 3)
        throw Error("detector: max corrected bits must be 0..3");
    detector_ = apriltag_detector_create();
    MR_CHECK(detector_ != nullptr, "apriltag_detector_create failed");
    apriltag_detector_add_family_bits(detector_, family_->raw(), options.maxHammingCorrected);
    detector_->quad_decimate = options.decimate;
    detector_->quad_sigma = options.blurSigma;
    detector_->refine_edges = options.refineEdges;
    detector_->decode_sharpening = options.decodeSharpening;
    detector_->nthreads = options.threads;
}

Detector::~Detector() {
    if (detector_) apriltag_detector_destroy(detector_);
}

Detector::Detector(Detector&& o) noexcept
    : options_(std::move(o.options_)),
      family_(std::move(o.family_)),
      detector_(std::exchange(o.detector_, nullptr)) {}

Detector& Detector::operator=(Detector&& o) noexcept {
    if (this != &o) {
        if (detector_) apriltag_detector_destroy(detector_);
        options_ = std::move(o.options_);
        family_ = std::move(o.family_);
        detector_ = std::exchange(o.detector_, nullptr);
    }
    return *this;
}

std::vector<TagDetection> Detector::detect(const cv::Mat& image) {
    return detect(image, cv::Rect(0, 0, image.cols, image.rows));
}

std::vector<TagDetection> Detector::detect(const cv::Mat& image, const cv::Rect& roi) {
    return detect(image, roi, options_.decimate, options_.fullResolutionRetry);
}

std::vector<TagDetection> Detector::detect(const cv::Mat& image, const cv::Rect& roiIn,
                                           float decimate, bool fullResolutionRetry) {
    if (!(decimate >= 1.0f)) throw Error("detector: decimate must be >= 1");
    MR_CHECK(detector_ != nullptr, "detect() on a moved-from Detector");
    cv::Mat grey;
    if (image.type() == CV_8UC1)
        grey = image.isContinuous() ? image : image.clone();
    else if (image.type() == CV_8UC3)
        cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
    else
        throw Error("detector: image must be 8-bit grey or BGR (got OpenCV type " +
                    std::to_string(image.type()) + ")");
    std::vector<TagDetection> out;
    if (grey.empty()) return out;
    const cv::Rect roi = roiIn & cv::Rect(0, 0, grey.cols, grey.rows);
    if (roi.width < 8 || roi.height < 8) return out;
    // A view of the region (rows keep the full image's stride): libapriltag reads only it.
    image_u8_t im{roi.width, roi.height, int(grey.step[0]), grey.ptr<uint8_t>(roi.y) + roi.x};
    detector_->quad_decimate = decimate;
    zarray_t* dets = apriltag_detector_detect(detector_, &im);
    float searchedDecimate = decimate;
    if (zarray_size(dets) == 0 && fullResolutionRetry && decimate > 1.0f) {
        apriltag_detections_destroy(dets);
        detector_->quad_decimate = searchedDecimate = 1.0f;
        dets = apriltag_detector_detect(detector_, &im);
    }
    detector_->quad_decimate = options_.decimate;
    out.reserve(size_t(zarray_size(dets)));
    for (int i = 0; i < zarray_size(dets); ++i) {
        apriltag_detection_t* d = nullptr;
        zarray_get(dets, i, &d);
        if (d->decision_margin < options_.minDecisionMargin) continue;
        TagDetection t;
        t.id = d->id;
        t.hamming = d->hamming;
        t.decisionMargin = d->decision_margin;
        // libapriltag puts pixel centres at +0.5 (its corner coordinates have the image origin at
        // the top-left pixel's corner); mirage uses OpenCV's convention (centres at integers).
        // Coordinates in the region are moved to the full image.
        const glm::dvec2 shift(roi.x - 0.5, roi.y - 0.5);
        t.centre = glm::dvec2(d->c[0], d->c[1]) + shift;
        for (int k = 0; k < 4; ++k)
            t.corners[size_t(k)] = glm::dvec2(d->p[k][0], d->p[k][1]) + shift;
        // With libapriltag's edge refinement its corners are within a few tenths of a pixel:
        // one pass. Without, they are up to the searched decimation off.
        if (options_.refineCorners)
            t.refined = options_.refineEdges
                            ? refineCorners(grey, family_->widthAtBorder(), t.corners)
                            : refineQuadCorners(grey, family_->widthAtBorder(), t.corners,
                                                double(searchedDecimate));
        out.push_back(t);
    }
    apriltag_detections_destroy(dets);
    return out;
}

}  // namespace mirage::tracking
