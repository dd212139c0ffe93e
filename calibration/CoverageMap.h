#pragma once
// What the captured views have covered so far: where in the image corners have landed (a grid
// of cells) and which board tilts have been seen (fronto-parallel and turned toward each side).
// Distortion is only constrained where corners landed, and the focal length only by tilted views
// (docs/calibration.md, "Coverage and advice").
// For a fish-eye lens, image cells say little about how far off-axis the data goes (the rim of
// the image circle is a thin ring of cells), so once a lens is set the map also counts corners by
// angle off the optical axis: rings of 20 degrees (0-20, ..., 60-80, 80+) times azimuth sectors,
// from the current camera estimate, and the fraction and the emptiest region speak in those bins.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"

namespace mirage::calib {

class CoverageMap {
public:
    CoverageMap(cv::Size imageSize, int cols = 8, int rows = 6);

    void add(const std::vector<cv::Point2f>& corners);  // pixels
    void clear();

    // Counts corners by angle off-axis through this lens from now on (the cells still count).
    // A (ring, sector) bin is reachable when the image border along the sector's centre azimuth
    // lies at least half a ring (10 degrees) past the ring's inner edge; only reachable bins
    // count in the fraction, and only rings with one are demanded. Call before add().
    void setAngularLens(const CameraIntrinsics& lens);
    bool angular() const { return lens_.has_value(); }
    static constexpr int kRingCount = 5;  // 0-20, 20-40, 40-60, 60-80, 80+ degrees
    static constexpr double kRingStepDeg = 20.0;
    static constexpr int kSectorCount = 8;  // azimuth sectors of 45 degrees, 0 = image right
    int ringCount(int ring) const;          // corners in a ring, all sectors
    int binCount(int ring, int sector) const { return bins_[size_t(ring * kSectorCount + sector)]; }
    // Rings with at least one reachable bin (angular mode only); the reachable rings are the
    // innermost ones.
    int reachableRings() const { return reachableRings_; }
    bool reachable(int ring, int sector) const {
        return reachableBins_[size_t(ring * kSectorCount + sector)] != 0;
    }
    // "no corners beyond 60 deg off-axis yet", "no corners between 20 and 40 deg off-axis yet":
    // one sentence per run of empty reachable rings; empty when every ring has a corner or the
    // map is not angular.
    std::vector<std::string> missingRings() const;

    int cols() const { return cols_; }
    int rows() const { return rows_; }
    int count(int col, int row) const { return counts_[size_t(row * cols_ + col)]; }
    // Cells with at least one corner / all cells; in angular mode, reachable (ring, sector) bins
    // with at least one corner / all reachable bins.
    double coveredFraction() const;
    // Centre (pixels) of the region (3x3 block of cells) with the fewest corners, and a name for
    // it ("top-left corner", "right edge", "centre", ...). In angular mode: the emptiest
    // reachable (ring, sector) bin, outer rings first on ties, named by its angles
    // ("60-80 deg off-axis, top right").
    cv::Point2f emptiestRegion(std::string& name) const;

private:
    cv::Size size_;
    int cols_, rows_;
    std::vector<int> counts_;
    std::optional<CameraIntrinsics> lens_;
    int reachableRings_ = 0;
    std::vector<int> bins_ = std::vector<int>(size_t(kRingCount * kSectorCount), 0);
    std::vector<char> reachableBins_ = std::vector<char>(size_t(kRingCount * kSectorCount), 0);
};

// Board tilt bins. A view's tilt is the angle between the board normal and the optical axis;
// its direction says where the board faces (the normal, pointing back at the camera, projected
// onto the image plane: +x = image right, +y = image down).
class TiltCoverage {
public:
    enum Bin { Fronto = 0, FacingRight, FacingLeft, FacingDown, FacingUp, BinCount };
    static const char* binName(Bin b);

    // Tilts under this are counted as fronto-parallel (degrees).
    explicit TiltCoverage(double tiltedDeg = 15.0) : tiltedDeg_(tiltedDeg) {}
    static Bin binOf(double tiltDeg, double directionDeg, double tiltedDeg);
    void add(double tiltDeg, double directionDeg);
    void clear();
    int count(Bin b) const { return counts_[size_t(b)]; }
    double maxTiltDeg() const { return maxTilt_; }
    // First tilted bin with no view yet, or BinCount if all have one.
    Bin missingBin() const;

private:
    double tiltedDeg_;
    std::array<int, BinCount> counts_{};
    double maxTilt_ = 0;
};

}  // namespace mirage::calib
