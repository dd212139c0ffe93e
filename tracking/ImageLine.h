#pragma once
// A straight line in the image (pixels) and the intersection of two: tag corners are where the
// fitted edge lines of a tag meet (Detector's refinement, PredictedTagFinder's edge search).
#include <cmath>

#include <glm/glm.hpp>

namespace mirage::tracking {

struct ImageLine {
    glm::dvec2 point{0.0};     // a point on the line (pixels)
    glm::dvec2 dir{1.0, 0.0};  // unit direction
};

// The intersection of a and b; false when they are (nearly) parallel (|sin angle| < 1e-6).
inline bool intersect(const ImageLine& a, const ImageLine& b, glm::dvec2& out) {
    const double det = a.dir.x * (-b.dir.y) - a.dir.y * (-b.dir.x);
    if (std::abs(det) < 1e-6) return false;
    const glm::dvec2 d = b.point - a.point;
    const double t = (d.x * (-b.dir.y) - d.y * (-b.dir.x)) / det;
    out = a.point + t * a.dir;
    return true;
}

}  // namespace mirage::tracking
