#include "calibration/CoverageMap.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "core/Error.h"

namespace mirage::calib {

CoverageMap::CoverageMap(cv::Size imageSize, int cols, int rows)
    : size_(imageSize), cols_(cols), rows_(rows), counts_(size_t(cols * rows), 0) {
    MR_CHECK(cols >= 3 && rows >= 3 && imageSize.width > 0 && imageSize.height > 0,
             "coverage grid needs at least 3x3 cells and a valid image size");
}

namespace {

// Angle off the optical axis (degrees) and azimuth (degrees, 0 = image right, 90 = image down)
// of a camera-frame ray.
void rayAngles(const glm::dvec3& ray, double& offAxisDeg, double& azimuthDeg) {
    offAxisDeg = std::atan2(std::hypot(ray.x, ray.y), ray.z) * 180.0 / CV_PI;
    azimuthDeg = std::fmod(std::atan2(ray.y, ray.x) * 180.0 / CV_PI + 360.0, 360.0);
}

std::string ringName(int ring) {
    const int lo = int(ring * CoverageMap::kRingStepDeg);
    if (ring + 1 >= CoverageMap::kRingCount) return fmt::format("{}+ deg off-axis", lo);
    return fmt::format("{}-{} deg off-axis", lo, int(lo + CoverageMap::kRingStepDeg));
}

const char* sectorName(int sector) {
    static const char* names[CoverageMap::kSectorCount] = {
        "right", "bottom right", "bottom", "bottom left", "left", "top left", "top", "top right"};
    return names[sector];
}

}  // namespace

void CoverageMap::setAngularLens(const CameraIntrinsics& lens) {
    MR_CHECK(lens.isValid(), "coverage by angle needs a valid lens");
    lens_ = lens;
    // A bin can be filled when the image reaches at least half a ring past its inner edge along
    // the sector's centre azimuth (from the principal point to the image border). So a ring that
    // only the image's corners touch (a fish-eye's 80+ ring in a 4:3 frame whose circle overfills
    // the width) is not demanded, while a circular fish-eye's rim ring is.
    const double maxDeg = lens.maxFisheyeTheta * 180.0 / CV_PI;
    const double w = size_.width - 1.0, h = size_.height - 1.0;
    reachableRings_ = 0;
    std::fill(reachableBins_.begin(), reachableBins_.end(), char(0));
    for (int sector = 0; sector < kSectorCount; ++sector) {
        const double a = (sector + 0.5) * (2 * CV_PI / kSectorCount);
        const double dx = std::cos(a), dy = std::sin(a);
        double t = std::numeric_limits<double>::infinity();
        if (dx > 1e-9) t = std::min(t, (w - lens.cx) / dx);
        if (dx < -1e-9) t = std::min(t, -lens.cx / dx);
        if (dy > 1e-9) t = std::min(t, (h - lens.cy) / dy);
        if (dy < -1e-9) t = std::min(t, -lens.cy / dy);
        double borderDeg = maxDeg;  // where the model does not invert, its trusted limit
        if (std::isfinite(t) && t > 0)
            if (const auto ray = lens.unproject({lens.cx + t * dx, lens.cy + t * dy})) {
                double off, az;
                rayAngles(*ray, off, az);
                borderDeg = std::min(off, maxDeg);
            }
        for (int ring = 0; ring < kRingCount; ++ring)
            if (borderDeg >= (ring + 0.5) * kRingStepDeg - 1e-6) {
                reachableBins_[size_t(ring * kSectorCount + sector)] = 1;
                reachableRings_ = std::max(reachableRings_, ring + 1);
            }
    }
}

void CoverageMap::add(const std::vector<cv::Point2f>& corners) {
    for (const auto& p : corners) {
        const int c = std::clamp(int(p.x / float(size_.width) * float(cols_)), 0, cols_ - 1);
        const int r = std::clamp(int(p.y / float(size_.height) * float(rows_)), 0, rows_ - 1);
        ++counts_[size_t(r * cols_ + c)];
        if (!lens_) continue;
        const auto ray = lens_->unproject({p.x, p.y});
        if (!ray) continue;  // beyond where the lens model inverts: no angle to count
        double off, az;
        rayAngles(*ray, off, az);
        const int ring = std::clamp(int(off / kRingStepDeg), 0, kRingCount - 1);
        const int sector = std::clamp(int(az / (360.0 / kSectorCount)), 0, kSectorCount - 1);
        ++bins_[size_t(ring * kSectorCount + sector)];
    }
}

void CoverageMap::clear() {
    std::fill(counts_.begin(), counts_.end(), 0);
    std::fill(bins_.begin(), bins_.end(), 0);
}

int CoverageMap::ringCount(int ring) const {
    int n = 0;
    for (int s = 0; s < kSectorCount; ++s) n += binCount(ring, s);
    return n;
}

std::vector<std::string> CoverageMap::missingRings() const {
    std::vector<std::string> out;
    if (!lens_) return out;
    for (int r = 0; r < reachableRings_;) {
        if (ringCount(r) > 0) {
            ++r;
            continue;
        }
        int end = r;  // one past the run of empty rings
        while (end < reachableRings_ && ringCount(end) == 0) ++end;
        const int lo = int(r * kRingStepDeg), hi = int(end * kRingStepDeg);
        if (end == reachableRings_)
            out.push_back(fmt::format("no corners beyond {} deg off-axis yet", lo));
        else if (r == 0)
            out.push_back(fmt::format("no corners within {} deg of the axis yet", hi));
        else
            out.push_back(fmt::format("no corners between {} and {} deg off-axis yet", lo, hi));
        r = end;
    }
    return out;
}

double CoverageMap::coveredFraction() const {
    if (lens_) {
        int n = 0, reachable = 0;
        for (size_t i = 0; i < bins_.size(); ++i)
            if (reachableBins_[i]) {
                ++reachable;
                n += bins_[i] > 0;
            }
        return reachable ? double(n) / double(reachable) : 0.0;
    }
    const auto n = std::count_if(counts_.begin(), counts_.end(), [](int c) { return c > 0; });
    return double(n) / double(counts_.size());
}

cv::Point2f CoverageMap::emptiestRegion(std::string& name) const {
    if (lens_) {
        // The emptiest reachable bin; ties go outward (the rim decides a fish-eye's distortion).
        int bestRing = 0, bestSector = 0, best = std::numeric_limits<int>::max();
        for (int r = reachableRings_ - 1; r >= 0; --r)
            for (int s = 0; s < kSectorCount; ++s)
                if (reachableBins_[size_t(r * kSectorCount + s)] && binCount(r, s) < best) {
                    best = binCount(r, s);
                    bestRing = r;
                    bestSector = s;
                }
        name = ringName(bestRing) + ", " + sectorName(bestSector);
        // Its centre direction, projected; the outermost ring's centre is kept inside the field.
        const double maxDeg = lens_->maxFisheyeTheta * 180.0 / CV_PI;
        const double off = std::min((bestRing + 0.5) * kRingStepDeg, maxDeg - 1.0) * CV_PI / 180.0;
        const double az = (bestSector + 0.5) * (2 * CV_PI / kSectorCount);
        const glm::dvec3 dir(std::sin(off) * std::cos(az), std::sin(off) * std::sin(az),
                             std::cos(off));
        if (const auto px = lens_->project(dir))
            return {std::clamp(float(px->x), 0.f, float(size_.width - 1)),
                    std::clamp(float(px->y), 0.f, float(size_.height - 1))};
        return {float(lens_->cx), float(lens_->cy)};
    }
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
