#include "calibration/SyntheticViews.h"

#include <cmath>

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/image/ImageIO.h"

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

CameraIntrinsics idealFisheye(FisheyeLens lens, double fovDeg, int width, int height) {
    if (!(fovDeg > 0 && fovDeg <= 240) || width <= 0 || height <= 0)
        throw Error(
            fmt::format("ideal fish-eye: field of view {} deg (need 0..240) or image "
                        "{}x{} invalid",
                        fovDeg, width, height));
    const double thetaMax = 0.5 * fovDeg * kDegToRad;
    auto radius = [lens](double theta) {  // image radius / f
        return lens == FisheyeLens::Equidistant ? theta : 2 * std::sin(0.5 * theta);
    };
    // theta_d / theta - 1 = k1 t^2 + k2 t^4 + k3 t^6 + k4 t^8, least squares over the field.
    const int samples = 400;
    cv::Mat A(samples, 4, CV_64F), b(samples, 1, CV_64F);
    for (int i = 0; i < samples; ++i) {
        const double t = thetaMax * (i + 1) / samples, t2 = t * t;
        double p = t2;
        for (int k = 0; k < 4; ++k, p *= t2) A.at<double>(i, k) = p;
        b.at<double>(i) = radius(t) / t - 1;
    }
    cv::Mat k;
    cv::solve(A, b, k, cv::DECOMP_SVD);
    CameraIntrinsics c;
    c.width = width;
    c.height = height;
    c.model = DistortionModel::KannalaBrandt;
    c.fx = c.fy = 0.5 * height / radius(thetaMax);
    c.cx = (width - 1) / 2.0;
    c.cy = (height - 1) / 2.0;
    c.distortion = {k.at<double>(0), k.at<double>(1), k.at<double>(2), k.at<double>(3)};
    c.maxFisheyeTheta = thetaMax;
    return c;
}

std::vector<cv::Point3f> ChessboardGeometry::corners() const {
    std::vector<cv::Point3f> pts;
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < cols; ++i)
            pts.emplace_back(float(i * squareMetres), float(j * squareMetres), 0.f);
    return pts;
}

BoardPose boardPoseFacing(const ChessboardGeometry& board, const cv::Vec3d& direction,
                          double distance, double tiltDeg, double tiltAxisDeg, double rollDeg) {
    const cv::Vec3d dir = direction / cv::norm(direction);
    const cv::Vec3d centreLocal((board.cols - 1) * board.squareMetres / 2,
                                (board.rows - 1) * board.squareMetres / 2, 0);
    const double axis = tiltAxisDeg * kDegToRad;
    cv::Matx33d Rroll, Rtilt;
    cv::Rodrigues(cv::Vec3d(0, 0, rollDeg * kDegToRad), Rroll);
    cv::Rodrigues(cv::Vec3d(std::cos(axis), std::sin(axis), 0) * (tiltDeg * kDegToRad), Rtilt);
    // Face the ray to the board centre, then tilt and roll: R maps board to camera axes.
    const cv::Matx33d R = rotationZTo(dir) * Rtilt * Rroll;
    BoardPose pose;
    cv::Rodrigues(R, pose.rvec);
    pose.tvec = dir * distance - R * centreLocal;
    return pose;
}

std::vector<BoardPose> sampleBoardPoses(const CameraIntrinsics& camera,
                                        const ChessboardGeometry& board, int count,
                                        const PoseSamplerOptions& o, std::mt19937& rng) {
    std::uniform_real_distribution<double> uni(0.0, 1.0);
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
        const BoardPose pose = boardPoseFacing(board, dir, dist, tilt / kDegToRad,
                                               tiltAxisAngle / kDegToRad, roll / kDegToRad);
        cv::Matx33d R;
        cv::Rodrigues(pose.rvec, R);
        const cv::Vec3d t = pose.tvec;
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
    : renderer_(camera, std::max(1, supersample)) {}

cv::Mat ChessboardRenderer::render(const ChessboardGeometry& board, const BoardPose& pose) const {
    // One texel per square: the (cols + 1) x (rows + 1) squares of the pattern start at (-sq, -sq)
    // (inner corner (0, 0) at the origin), with one white square of margin all around.
    constexpr uint8_t kBlack = 25, kWhite = 230;
    const double sq = board.squareMetres;
    cv::Mat texture(board.rows + 3, board.cols + 3, CV_8UC1, cv::Scalar(kWhite));
    for (int v = 1; v <= board.rows + 1; ++v)
        for (int u = 1; u <= board.cols + 1; ++u)
            if (((u + v) & 1) == 0) texture.at<uint8_t>(v, u) = kBlack;
    return renderTexture(texture, sq, {2.0, 2.0}, pose);
}

cv::Mat ChessboardRenderer::renderTexture(const cv::Mat& texture, double metresPerTexel,
                                          const cv::Point2d& boardOriginTexel,
                                          const BoardPose& pose) const {
    MR_CHECK(texture.type() == CV_8UC1 && metresPerTexel > 0, "texture must be 8-bit grey");
    PlaneTexture plane;
    plane.image = texture;
    plane.metresPerTexelX = plane.metresPerTexelY = metresPerTexel;
    plane.originMetres = {-boardOriginTexel.x * metresPerTexel,
                          -boardOriginTexel.y * metresPerTexel};
    plane.filter = PlaneTexture::Filter::Nearest;
    PlaneShading shading;  // texture values are the output levels
    shading.background = kBackground;
    cv::Matx33d R;
    cv::Rodrigues(pose.rvec, R);
    glm::dmat3 Rg;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) Rg[c][r] = R(r, c);
    const Pose T_camera_board =
        Pose::fromRotationTranslation(Rg, glm::dvec3(pose.tvec[0], pose.tvec[1], pose.tvec[2]));
    return renderer_.render(plane, T_camera_board, shading);
}

cv::Mat blurInLinearLight(const cv::Mat& srgbGrey, double sigmaPx) {
    MR_CHECK(srgbGrey.type() == CV_8UC1, "blurInLinearLight: 8-bit grey image expected");
    if (!(sigmaPx > 0)) return srgbGrey.clone();
    cv::Mat lut(1, 256, CV_32F);
    for (int i = 0; i < 256; ++i) lut.at<float>(i) = srgbToLinear(float(i) / 255.0f);
    cv::Mat linear, blurred;
    cv::LUT(srgbGrey, lut, linear);
    cv::GaussianBlur(linear, blurred, cv::Size(), sigmaPx);
    cv::Mat out(srgbGrey.size(), CV_8UC1);
    for (int y = 0; y < out.rows; ++y)
        for (int x = 0; x < out.cols; ++x)
            out.at<uint8_t>(y, x) = uint8_t(std::lround(
                255.0f * linearToSrgb(std::clamp(blurred.at<float>(y, x), 0.0f, 1.0f))));
    return out;
}

cv::Mat renderChessboard(const CameraIntrinsics& camera, const ChessboardGeometry& board,
                         const BoardPose& pose, int supersample) {
    return ChessboardRenderer(camera, supersample).render(board, pose);
}

}  // namespace mirage::calib
