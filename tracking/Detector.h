#pragma once
// AprilTag detection: RAII over libapriltag's detector (docs/tracking.md, "Detector").
#include <array>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

struct apriltag_detector;

namespace mirage::tracking {

class TagFamily;

struct DetectorOptions {
    // libapriltag family name (TagFamily::supportedNames()).
    std::string family = "tag36h11";
    // Quads are searched on an image decimated by this factor (1 = full resolution). 2 is about
    // 3x faster; the corners are then snapped back to full-resolution edges (refineEdges), so
    // accuracy drops little, but tags under ~25 px may be missed. libapriltag default: 2.
    float decimate = 2.0f;
    // When decimating finds no tag at all, search once more at full resolution: small or distant
    // tags are then still found, at the full-resolution cost only in frames that need it.
    bool fullResolutionRetry = true;
    // Gaussian blur sigma (pixels) before quad search; 0 = none. ~0.8 helps on noisy images.
    float blurSigma = 0.0f;
    // Snap quad edges to strong full-resolution gradients (libapriltag applies it at any
    // decimation; after a decimated quad search it restores the full-resolution edge).
    bool refineEdges = true;
    // Sharpening of the sampled code bits, helps small tags. libapriltag default: 0.25.
    double decodeSharpening = 0.25;
    // Worker threads for the detector (1 = in the calling thread).
    int threads = 1;
    // Bit errors corrected when decoding. 36h11 has Hamming distance 11; correcting more bits
    // finds damaged tags but admits false positives. libapriltag's default is 2; mirage uses 1.
    int maxHammingCorrected = 1;
    // mirage's sub-pixel edge refinement after libapriltag: each border edge is located where the
    // linearised (sRGB-decoded) intensity crosses midway between the black border and the white
    // quiet zone, a line is fitted per edge and the corners are the lines' intersections. This
    // removes libapriltag's ~0.15-0.2 px inward bias of the corners. Off = libapriltag's corners
    // (shifted to OpenCV's pixel convention).
    bool refineCorners = true;
    // Detections with a decision margin below this are dropped (libapriltag's quality measure of
    // the bit decoding; real tags are typically > 30, noise-born false detections < 20).
    float minDecisionMargin = 20.0f;
};

struct TagDetection {
    int id = -1;
    // Detection corners in pixels (pixel (0,0) = centre of the top-left pixel), libapriltag's
    // order, counter-clockwise in the image: BoardTag::cornersInTag() gives the matching tag-frame
    // points (0 = bottom-left, 1 = bottom-right, 2 = top-right, 3 = top-left of the printed tag).
    std::array<glm::dvec2, 4> corners{};
    glm::dvec2 centre{0.0};
    float decisionMargin = 0;
    int hamming = 0;
    // The corners went through mirage's sub-pixel refinement (Detector::refineCorners); false:
    // libapriltag's corners (refinement off or failed), less precise after strong decimation.
    bool refined = false;
    // Width of the image's edges around the tag (pixels, about 2 for a sharp image and the
    // motion-blur length beyond that; tagEdgeWidthPx in Tracker.h), or -1: not measured. The
    // pose estimator's corner-noise prior grows with it.
    double edgeWidthPx = -1;
};

class Detector {
public:
    explicit Detector(const DetectorOptions& options = {});
    ~Detector();
    Detector(Detector&&) noexcept;
    Detector& operator=(Detector&&) noexcept;
    Detector(const Detector&) = delete;
    Detector& operator=(const Detector&) = delete;

    // Detects tags in an 8-bit image: CV_8UC1 grey, or CV_8UC3 BGR (converted to grey). Throws
    // mirage::Error on another type. Not thread-safe: one Detector per thread.
    std::vector<TagDetection> detect(const cv::Mat& image);
    // The same, searching for quads only inside `roi` (pixels, clipped to the image; no copy):
    // the cost of libapriltag scales with the area searched. Corners are in full-image pixels
    // and refined on the full image.
    std::vector<TagDetection> detect(const cv::Mat& image, const cv::Rect& roi);
    // The same at `decimate` instead of DetectorOptions::decimate, with or without the
    // full-resolution retry (DetectorOptions::fullResolutionRetry): a caller that has a cheaper
    // retry of its own runs the decimated search alone first.
    std::vector<TagDetection> detect(const cv::Mat& image, const cv::Rect& roi, float decimate,
                                     bool fullResolutionRetry);

    const DetectorOptions& options() const { return options_; }

    // mirage's sub-pixel edge refinement (DetectorOptions::refineCorners) of a tag's detection
    // corners in an 8-bit grey sRGB-encoded image, from corners within ~0.45 cell of the truth
    // (cellsAtBorder: TagFamily::widthAtBorder()). Returns false and leaves the corners unchanged
    // when an edge cannot be measured (occluded, damaged, next to dark surroundings) or a corner
    // would move by more than maxMovePx. Also used by the tracking mode (PredictedTagFinder).
    static bool refineCorners(const cv::Mat& grey, int cellsAtBorder,
                              std::array<glm::dvec2, 4>& corners, double maxMovePx = 1.5);
    // The refinement of corners a quad search found to within startErrorPx (libapriltag's
    // corners on an image decimated by d, without its own edge refinement, are up to ~d px off):
    // a corner may move by up to max(1.5, startErrorPx), and a second pass runs when the first
    // moved a corner by more than kSecondPassMovePx, because a pass that starts ~1 px off samples
    // profiles skewed along the edges (measured: up to 0.47 px corner error left on a 31 px tag,
    // 0.2 px after the second pass). After a small move a second pass changes little and costs as
    // much. Returns false (corners unchanged) when a pass fails.
    static bool refineQuadCorners(const cv::Mat& grey, int cellsAtBorder,
                                  std::array<glm::dvec2, 4>& corners, double startErrorPx);
    static constexpr double kSecondPassMovePx = 0.25;

private:
    DetectorOptions options_;
    std::unique_ptr<TagFamily> family_;
    apriltag_detector* detector_ = nullptr;
};

}  // namespace mirage::tracking
