#include "render/reconstruction/FootageCheck.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace mirage::reconstruction {

FootageCheck checkFootage(const Footage& footage, const FootageCheckOptions& options) {
    FootageCheck c;
    c.frames = int(footage.frames.size());
    std::vector<glm::dvec3> centres;
    std::vector<double> distances;
    for (const auto& f : footage.frames) {
        centres.push_back(f.T_world_camera.translation);
        distances.push_back(glm::length(f.T_world_camera.translation - footage.board.point));
    }
    if (!distances.empty()) {
        std::nth_element(distances.begin(), distances.begin() + long(distances.size() / 2),
                         distances.end());
        c.medianDistanceM = distances[distances.size() / 2];
    }
    for (size_t i = 0; i < centres.size(); ++i)
        for (size_t j = i + 1; j < centres.size(); ++j) {
            c.maxBaselineM = std::max(c.maxBaselineM, glm::length(centres[i] - centres[j]));
            const glm::dvec3 a = centres[i] - footage.board.point;
            const glm::dvec3 b = centres[j] - footage.board.point;
            const double la = glm::length(a), lb = glm::length(b);
            if (la <= 0 || lb <= 0) continue;
            const double cosAngle = std::clamp(glm::dot(a, b) / (la * lb), -1.0, 1.0);
            c.parallaxDeg = std::max(c.parallaxDeg, glm::degrees(std::acos(cosAngle)));
        }
    if (c.frames < options.minFrames) {
        c.problem = fmt::format(
            "only {} tracked frame(s) (tracking state ok), at least {} are needed; record again "
            "with the whole tag board in view, moving slowly enough that the tags stay sharp",
            c.frames, options.minFrames);
        return c;
    }
    if (c.parallaxDeg < options.minParallaxDeg) {
        c.problem = fmt::format(
            "the camera hardly moved sideways: seen from the board's centre the camera positions "
            "span {:.1f} degrees (largest distance between two of them {:.1f} cm), at least {:.0f} "
            "are needed; turning the camera on the spot (a pure rotation) shows no depth. Record "
            "again walking the camera around the table in an arc of 30 degrees or more, keeping "
            "the board in view",
            c.parallaxDeg, 100.0 * c.maxBaselineM, options.minParallaxDeg);
        return c;
    }
    c.ok = true;
    return c;
}

}  // namespace mirage::reconstruction
