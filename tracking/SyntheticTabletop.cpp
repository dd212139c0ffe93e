#include "tracking/SyntheticTabletop.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "tracking/BoardImage.h"

namespace mirage::tracking {

cv::Mat valueNoiseTexture(int size, uint32_t seed) {
    cv::RNG rng(seed);
    cv::Mat acc(size, size, CV_32F, cv::Scalar(0));
    for (int cells : {size / 64, size / 16, size / 6}) {
        cv::Mat small(std::max(2, cells), std::max(2, cells), CV_32F);
        rng.fill(small, cv::RNG::UNIFORM, 0.0, 1.0);
        cv::Mat big;
        cv::resize(small, big, acc.size(), 0, 0, cv::INTER_CUBIC);
        acc += big;
    }
    cv::Mat out;
    cv::normalize(acc, acc, 25, 230, cv::NORM_MINMAX);
    acc.convertTo(out, CV_8U);
    return out;
}

SyntheticTabletop::SyntheticTabletop(Board board, double halfSizeM, double metresPerTexel,
                                     uint32_t seed)
    : board_(std::move(board)) {
    if (!board_.sheet) throw Error("synthetic tabletop: the board has no sheet to paste");
    const int n = int(std::lround(2 * halfSizeM / metresPerTexel));
    texture_.image = valueNoiseTexture(n, seed);
    texture_.metresPerTexelX = texture_.metresPerTexelY = metresPerTexel;
    texture_.originMetres = {-halfSizeM, -halfSizeM};
    // The sheet frame's origin is the sheet's centre; its raster at the table's texel size.
    const BoardRaster sheet = renderBoard(board_, 1.0 / metresPerTexel, false);
    const int x0 = int(std::lround((halfSizeM - 0.5 * board_.sheet->width) / metresPerTexel));
    const int y0 = int(std::lround((halfSizeM - 0.5 * board_.sheet->height) / metresPerTexel));
    const cv::Rect at = cv::Rect(x0, y0, sheet.image.cols, sheet.image.rows) &
                        cv::Rect(0, 0, texture_.image.cols, texture_.image.rows);
    sheet.image(cv::Rect(0, 0, at.width, at.height)).copyTo(texture_.image(at));
}

cv::Mat SyntheticTabletop::render(const TexturedPlaneRenderer& renderer,
                                  const Pose& T_world_camera) const {
    return renderer.render(texture_, T_world_camera.inverse() * board_.sheet->T_world_sheet);
}

Pose orbitThenPan(int frame, int orbitFrames, int panFrames, double panDeg, double distanceM,
                  double elevationDeg) {
    const int k = std::clamp(frame, 0, orbitFrames - 1);
    const double az = glm::radians(-15.0 + 30.0 * k / std::max(1, orbitFrames - 1));
    const double el = glm::radians(elevationDeg);
    const glm::dvec3 eye = distanceM * glm::dvec3(std::cos(el) * std::sin(az), std::sin(el),
                                                  std::cos(el) * std::cos(az));
    // Looking at the origin with the board's far edge (-Z) up in the image.
    Pose T = cameraLookingAt(eye, glm::dvec3(0.0), glm::dvec3(0, 0, -1));
    if (frame < orbitFrames) return T;
    const double u = std::min(1.0, double(frame - orbitFrames + 1) / std::max(1, panFrames));
    const double yaw = glm::radians(panDeg) * (0.5 - 0.5 * std::cos(M_PI * u));
    T.rotation = glm::normalize(glm::angleAxis(yaw, glm::dvec3(0, 1, 0)) * T.rotation);
    return T;
}

bool boardInView(const CameraIntrinsics& camera, const Board& board, const Pose& T_world_camera) {
    const Pose Tcw = T_world_camera.inverse();
    for (const auto& tag : board.tags)
        for (const auto& c : tag.cornersInWorld()) {
            const glm::dvec3 Xc = Tcw * c;
            if (Xc.z <= 0) continue;
            const auto px = camera.project(Xc);
            if (px && px->x >= 0 && px->y >= 0 && px->x < camera.width && px->y < camera.height)
                return true;
        }
    return false;
}

}  // namespace mirage::tracking
