#include "calibration/CoverageMap.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/Error.h"

namespace mirage::calib {

CoverageMap::CoverageMap(cv::Size imageSize, int cols, int rows)
    : size_(imageSize), cols_(cols), rows_(rows), counts_(size_t(cols * rows), 0) {
    MR_CHECK(cols >= 3 && rows >= 3 && imageSize.width > 0 && imageSize.height > 0,
             "coverage grid needs at least 3x3 cells and a valid image size");
}

void CoverageMap::add(const std::vector<cv::Point2f>& corners) {
    for (const auto& p : corners) {
        const int c = std::clamp(int(p.x / float(size_.width) * float(cols_)), 0, cols_ - 1);
        const int r = std::clamp(int(p.y / float(size_.height) * float(rows_)), 0, rows_ - 1);
        ++counts_[size_t(r * cols_ + c)];
    }
}

void CoverageMap::clear() {
    std::fill(counts_.begin(), counts_.end(), 0);
}

double CoverageMap::coveredFraction() const {
    const auto n = std::count_if(counts_.begin(), counts_.end(), [](int c) { return c > 0; });
    return double(n) / double(counts_.size());
}

cv::Point2f CoverageMap::emptiestRegion(std::string& name) const {
    // Slide a 3x3 block over the grid; ties go to the block farthest from the centre, because
    // the image's edges and corners are where distortion needs corners most.
    int bestC = 0, bestR = 0;
    long bestSum = std::numeric_limits<long>::max();
    double bestDist = -1;
    for (int r = 0; r + 3 <= rows_; ++r)
        for (int c = 0; c + 3 <= cols_; ++c) {
            long sum = 0;
            for (int dr = 0; dr < 3; ++dr)
                for (int dc = 0; dc < 3; ++dc) sum += count(c + dc, r + dr);
            const double dx = (c + 1.5) / cols_ - 0.5, dy = (r + 1.5) / rows_ - 0.5;
            const double dist = dx * dx + dy * dy;
            if (sum < bestSum || (sum == bestSum && dist > bestDist)) {
                bestSum = sum;
                bestDist = dist;
                bestC = c;
                bestR = r;
            }
        }
    const float x = (float(bestC) + 1.5f) / float(cols_), y = (float(bestR) + 1.5f) / float(rows_);
    const char* v = y < 0.4f ? "top" : y > 0.6f ? "bottom" : "";
    const char* h = x < 0.4f ? "left" : x > 0.6f ? "right" : "";
    if (*v && *h)
        name = std::string(v) + "-" + h + " corner";
    else if (*v)
        name = std::string(v) + " edge";
    else if (*h)
        name = std::string(h) + " edge";
    else
        name = "centre";
    return {x * float(size_.width), y * float(size_.height)};
}

const char* TiltCoverage::binName(Bin b) {
    switch (b) {
        case Fronto:
            return "fronto-parallel";
        case FacingRight:
            return "facing right";
        case FacingLeft:
            return "facing left";
        case FacingDown:
            return "facing down";
        case FacingUp:
            return "facing up";
        default:
            return "?";
    }
}

TiltCoverage::Bin TiltCoverage::binOf(double tiltDeg, double directionDeg, double tiltedDeg) {
    if (tiltDeg < tiltedDeg) return Fronto;
    double d = std::fmod(directionDeg + 360.0, 360.0);
    if (d < 45 || d >= 315) return FacingRight;
    if (d < 135) return FacingDown;  // image +y is down
    if (d < 225) return FacingLeft;
    return FacingUp;
}

void TiltCoverage::add(double tiltDeg, double directionDeg) {
    ++counts_[size_t(binOf(tiltDeg, directionDeg, tiltedDeg_))];
    maxTilt_ = std::max(maxTilt_, tiltDeg);
}

void TiltCoverage::clear() {
    counts_.fill(0);
    maxTilt_ = 0;
}

TiltCoverage::Bin TiltCoverage::missingBin() const {
    for (int b = FacingRight; b < BinCount; ++b)
        if (counts_[size_t(b)] == 0) return Bin(b);
    return BinCount;
}

}  // namespace mirage::calib
