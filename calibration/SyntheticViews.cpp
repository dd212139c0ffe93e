#include "calibration/SyntheticViews.h"

#include <cmath>

#include <opencv2/calib3d.hpp>

#include "core/Error.h"

namespace mirage::calib {
namespace {
constexpr double kDegToRad = 0.017453292519943295;

// Rotation taking +Z onto the unit vector `dir` (shortest arc).
cv::Matx33d rotationZTo(const cv::Vec3d& dir) {
    const cv::Vec3d z(0, 0, 1);
    cv::Vec3d axis = z.cross(dir);
    const double s = cv::norm(axis), c = z.dot(dir);
    if (s < 1e-12) return c > 0 ? cv::Matx33d::eye() : cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1);
    cv::Vec3d rv = axis * (std::atan2(s, c) / s);
    cv::Matx33d R;
    cv::Rodrigues(rv, R);
    return R;
}
}  // namespace

std::vector<cv::Point3f> ChessboardGeometry::corners() const {
    std::vector<cv::Point3f> pts;
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < cols; ++i)
            pts.emplace_back(float(i * squareMetres), float(j * squareMetres), 0.f);
    return pts;
}

std::vector<BoardPose> sampleBoardPoses(const CameraIntrinsics& camera,
                                        const ChessboardGeometry& board, int count,
                                        const PoseSamplerOptions& o, std::mt19937& rng) {
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    const cv::Vec3d centreLocal((board.cols - 1) * board.squareMetres / 2,
                                (board.rows - 1) * board.squareMetres / 2, 0);
    const auto corners = board.corners();
    std::vector<BoardPose> poses;
    int attempts = 0;
    while (int(poses.size()) < count) {
        if (++attempts > 2000 * count)
            throw Error(
                "synthetic views: cannot place the board fully inside the image with "
                "these options (board too large or distance too small)");
        const double u = camera.width * (0.5 + o.imageSpread * (uni(rng) - 0.5));
        const double v = camera.height * (0.5 + o.imageSpread * (uni(rng) - 0.5));
        const auto ray = camera.unproject({u, v});
        if (!ray) continue;
        const cv::Vec3d dir(ray->x, ray->y, ray->z);
        const double dist = o.minDistance + (o.maxDistance - o.minDistance) * uni(rng);
        const double tilt = (o.minTiltDeg + (o.maxTiltDeg - o.minTiltDeg) * uni(rng)) * kDegToRad;
        const double tiltAxisAngle = 2 * M_PI * uni(rng);
        const double roll = o.maxRollDeg * (2 * uni(rng) - 1) * kDegToRad;
        cv::Matx33d Rroll, Rtilt;
        cv::Rodrigues(cv::Vec3d(0, 0, roll), Rroll);
        cv::Rodrigues(cv::Vec3d(std::cos(tiltAxisAngle), std::sin(tiltAxisAngle), 0) * tilt, Rtilt);
        // Face the ray to the board centre, then tilt and roll: R maps board to camera axes.
        const cv::Matx33d R = rotationZTo(dir) * Rtilt * Rroll;
        const cv::Vec3d t = dir * dist - R * centreLocal;
        BoardPose pose;
        cv::Rodrigues(R, pose.rvec);
        pose.tvec = t;
        if (o.requireFullyVisible) {
            bool inside = true;
            for (const auto& c : corners) {
                const cv::Vec3d pc = R * cv::Vec3d(c.x, c.y, c.z) + t;
                const auto px = camera.project({pc[0], pc[1], pc[2]});
                if (!px || px->x < o.marginPx || px->y < o.marginPx ||
                    px->x > camera.width - 1 - o.marginPx ||
                    px->y > camera.height - 1 - o.marginPx) {
                    inside = false;
                    break;
                }
            }
            if (!inside) continue;
        }
        poses.push_back(pose);
    }
    return poses;
}

CalibrationView projectView(const CameraIntrinsics& camera, const ChessboardGeometry& board,
                            const BoardPose& pose, double noisePx, std::mt19937& rng,
                            const std::string& name) {
    std::normal_distribution<double> noise(0.0, 1.0);
    cv::Matx33d R;
    cv::Rodrigues(pose.rvec, R);
    CalibrationView view;
    view.name = name;
    for (const auto& c : board.corners()) {
        const cv::Vec3d pc = R * cv::Vec3d(c.x, c.y, c.z) + pose.tvec;
        const auto px = camera.project({pc[0], pc[1], pc[2]});
        const double nx = noisePx * noise(rng), ny = noisePx * noise(rng);
        if (!px) continue;
        const double x = px->x + nx, y = px->y + ny;
        if (x < 0 || y < 0 || x > camera.width - 1 || y > camera.height - 1) continue;
        view.imagePoints.emplace_back(float(x), float(y));
        view.boardPoints.push_back(c);
    }
    return view;
}

ChessboardRenderer::ChessboardRenderer(const CameraIntrinsics& camera, int supersample)
    : camera_(camera), n_(std::max(1, supersample)) {
    rays_.resize(size_t(camera.width) * size_t(camera.height) * size_t(n_ * n_));
    size_t k = 0;
    for (int y = 0; y < camera.height; ++y)
        for (int x = 0; x < camera.width; ++x)
            for (int sy = 0; sy < n_; ++sy)
                for (int sx = 0; sx < n_; ++sx) {
                    // Pixel (x, y) covers [x - 0.5, x + 0.5] (OpenCV: centres at integers).
                    const glm::dvec2 px{x - 0.5 + (sx + 0.5) / n_, y - 0.5 + (sy + 0.5) / n_};
                    const auto ray = camera.unproject(px);
                    rays_[k++] = ray ? cv::Vec3f(float(ray->x), float(ray->y), float(ray->z))
                                     : cv::Vec3f(0, 0, 0);
                }
}

template <typename ShadeBoardPoint>
cv::Mat ChessboardRenderer::renderPlane(const BoardPose& pose, ShadeBoardPoint shade) const {
    cv::Matx33d R;
    cv::Rodrigues(pose.rvec, R);
    const cv::Matx33d Rt = R.t();
    const cv::Vec3d origin = -(Rt * pose.tvec);  // camera centre in board coordinates
    cv::Mat img(camera_.height, camera_.width, CV_8UC1);
    size_t k = 0;
    for (int y = 0; y < camera_.height; ++y) {
        auto* row = img.ptr<uint8_t>(y);
        for (int x = 0; x < camera_.width; ++x) {
            double sum = 0;
            for (int s = 0; s < n_ * n_; ++s) {
                const cv::Vec3f& r = rays_[k++];
                double value = kBackground;
                const cv::Vec3d d = Rt * cv::Vec3d(r[0], r[1], r[2]);
                if (std::abs(d[2]) > 1e-12) {
                    const double t = -origin[2] / d[2];
                    if (t > 0) value = shade(origin[0] + t * d[0], origin[1] + t * d[1]);
                }
                sum += value;
            }
            row[x] = cv::saturate_cast<uint8_t>(sum / (n_ * n_));
        }
    }
    return img;
}

cv::Mat ChessboardRenderer::render(const ChessboardGeometry& board, const BoardPose& pose) const {
    const double sq = board.squareMetres;
    return renderPlane(pose, [&](double bx, double by) {
        // Squares span [-sq, cols*sq] x [-sq, rows*sq]; margin of 1 square.
        const double gx = bx / sq + 1, gy = by / sq + 1;
        if (gx < -1 || gy < -1 || gx >= board.cols + 2 || gy >= board.rows + 2) return kBackground;
        if (gx >= 0 && gy >= 0 && gx < board.cols + 1 && gy < board.rows + 1 &&
            ((int(std::floor(gx)) + int(std::floor(gy))) & 1) == 0)
            return 25.0;
        return 230.0;
    });
}

cv::Mat ChessboardRenderer::renderTexture(const cv::Mat& texture, double metresPerTexel,
                                          const cv::Point2d& boardOriginTexel,
                                          const BoardPose& pose) const {
    MR_CHECK(texture.type() == CV_8UC1 && metresPerTexel > 0, "texture must be 8-bit grey");
    return renderPlane(pose, [&](double bx, double by) {
        const double u = std::floor(bx / metresPerTexel + boardOriginTexel.x);
        const double v = std::floor(by / metresPerTexel + boardOriginTexel.y);
        if (u < 0 || v < 0 || u >= texture.cols || v >= texture.rows) return kBackground;
        return double(texture.at<uint8_t>(int(v), int(u)));
    });
}

cv::Mat renderChessboard(const CameraIntrinsics& camera, const ChessboardGeometry& board,
                         const BoardPose& pose, int supersample) {
    return ChessboardRenderer(camera, supersample).render(board, pose);
}

}  // namespace mirage::calib
