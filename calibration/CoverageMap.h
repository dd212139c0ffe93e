#pragma once
// What the captured views have covered so far: where in the image corners have landed (a grid
// of cells) and which board tilts have been seen (fronto-parallel and turned toward each side).
// Distortion is only constrained where corners landed, and the focal length only by tilted views
// (docs/calibration.md, "Coverage and advice").
#include <array>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace mirage::calib {

class CoverageMap {
public:
    CoverageMap(cv::Size imageSize, int cols = 8, int rows = 6);

    void add(const std::vector<cv::Point2f>& corners);  // pixels
    void clear();

    int cols() const { return cols_; }
    int rows() const { return rows_; }
    int count(int col, int row) const { return counts_[size_t(row * cols_ + col)]; }
    // Cells with at least one corner / all cells.
    double coveredFraction() const;
    // Centre (pixels) of the region (3x3 block of cells) with the fewest corners, and a name for
    // it ("top-left corner", "right edge", "centre", ...).
    cv::Point2f emptiestRegion(std::string& name) const;

private:
    cv::Size size_;
    int cols_, rows_;
    std::vector<int> counts_;
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
