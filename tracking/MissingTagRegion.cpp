#include "tracking/MissingTagRegion.h"

#include <algorithm>
#include <cmath>

namespace mirage::tracking {

MissingTags findMissingTags(const Board& board, const CameraIntrinsics& camera,
                            const Pose& T_world_camera, const std::vector<TagDetection>& found,
                            const MissingTagOptions& options) {
    MissingTags out;
    const Pose T_camera_world = T_world_camera.inverse();
    const double b = options.borderPx;
    double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
    for (const auto& tag : board.tags) {
        std::array<glm::dvec2, 4> px{};
        bool inside = true;
        const auto corners = tag.cornersInWorld();
        for (size_t k = 0; k < 4 && inside; ++k) {
            const glm::dvec3 Xc = T_camera_world * corners[k];
            const auto p = Xc.z > 1e-3 ? camera.project(Xc) : std::nullopt;
            inside = p && p->x >= b && p->y >= b && p->x <= camera.width - 1 - b &&
                     p->y <= camera.height - 1 - b;
            if (p) px[k] = *p;
        }
        if (!inside) continue;
        double shortest = 1e18, longest = 0;
        for (size_t k = 0; k < 4; ++k) {
            const double side = glm::length(px[k] - px[(k + 1) % 4]);
            shortest = std::min(shortest, side);
            longest = std::max(longest, side);
        }
        if (shortest < options.minSidePx) continue;
        ++out.predicted;
        const bool have = std::any_of(found.begin(), found.end(),
                                      [&](const TagDetection& d) { return d.id == tag.id; });
        if (have) continue;
        out.ids.push_back(tag.id);
        const double m = options.marginFraction * longest + options.marginPx;
        for (const auto& p : px) {
            x0 = std::min(x0, p.x - m);
            y0 = std::min(y0, p.y - m);
            x1 = std::max(x1, p.x + m);
            y1 = std::max(y1, p.y + m);
        }
    }
    if (out.ids.empty()) return out;
    // Origin aligned down to 8 pixels, as the tracker's other regions (libapriltag's tiles).
    const int bx0 = std::max(0, int(std::floor(x0)) / 8 * 8);
    const int by0 = std::max(0, int(std::floor(y0)) / 8 * 8);
    const int bx1 = std::min(camera.width, int(std::ceil(x1)));
    const int by1 = std::min(camera.height, int(std::ceil(y1)));
    if (bx1 > bx0 && by1 > by0) out.region = cv::Rect(bx0, by0, bx1 - bx0, by1 - by0);
    return out;
}

}  // namespace mirage::tracking
