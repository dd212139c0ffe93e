#include "calibration/FisheyeMonteCarlo.h"

#include <cmath>
#include <limits>
#include <random>

#include <opencv2/calib3d.hpp>

#include "calibration/CalibrationTarget.h"
#include "calibration/Calibrator.h"
#include "core/Error.h"

namespace mirage::calib {
namespace {

constexpr double kDeg = M_PI / 180.0;

bool fullyVisible(const CameraIntrinsics& cam, const ChessboardGeometry& board,
                  const BoardPose& pose, double marginPx) {
    cv::Matx33d R;
    cv::Rodrigues(pose.rvec, R);
    // The white margin too (one square around the corners): the detectors need it.
    const double sq = board.squareMetres;
    for (double x = -sq; x <= board.cols * sq + 1e-9; x += sq / 2)
        for (double y = -sq; y <= board.rows * sq + 1e-9; y += sq / 2) {
            const cv::Vec3d p = R * cv::Vec3d(x, y, 0) + pose.tvec;
            const auto px = cam.project({p[0], p[1], p[2]});
            if (!px || px->x < marginPx || px->y < marginPx || px->x > cam.width - 1 - marginPx ||
                px->y > cam.height - 1 - marginPx)
                return false;
        }
    return true;
}

// Half the views anywhere in the image, half with the board centre 70-95 % of the way to the
// rim of the image circle, facing the camera within 35 degrees.
std::vector<BoardPose> drawPoses(const CameraIntrinsics& cam, const ChessboardGeometry& board,
                                 int count, std::mt19937& rng) {
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    std::vector<BoardPose> poses;
    const double thetaMax = cam.maxFisheyeTheta;
    for (int attempts = 0; int(poses.size()) < count; ++attempts) {
        if (attempts > 20000 * count)
            throw Error("fish-eye Monte-Carlo: cannot place the board inside the image");
        const bool rim = poses.size() % 2 == 1;
        const double theta = rim ? thetaMax * (0.7 + 0.25 * uni(rng)) : thetaMax * 0.7 * uni(rng);
        const double azimuth = 2 * M_PI * uni(rng);
        const cv::Vec3d dir(std::sin(theta) * std::cos(azimuth),
                            std::sin(theta) * std::sin(azimuth), std::cos(theta));
        const double distance = 0.14 + 0.16 * uni(rng);
        const double tilt = rim ? 35 * uni(rng) : 10 + 40 * uni(rng);
        const BoardPose pose =
            boardPoseFacing(board, dir, distance, tilt, 360 * uni(rng), 40 * (2 * uni(rng) - 1));
        if (fullyVisible(cam, board, pose, 3.0)) poses.push_back(pose);
    }
    return poses;
}

// Mean and maximum projection difference (pixels) between two models over directions up to
// maxDeg off-axis (1-degree rings, 10-degree azimuth steps); `stated` gets the mean of
// projectionStdPx over the same directions when a covariance is given.
void compare(const CameraIntrinsics& truth, const CameraIntrinsics& model, double maxDeg,
             double& meanPx, double& maxPx, const cv::Mat* covariance = nullptr,
             double* stated = nullptr) {
    double sum = 0, sumStd = 0, worst = 0;
    int n = 0;
    for (double t = 0; t <= maxDeg + 1e-9; t += 1.0)
        for (double a = 0; a < 360; a += 10) {
            const glm::dvec3 d(std::sin(t * kDeg) * std::cos(a * kDeg),
                               std::sin(t * kDeg) * std::sin(a * kDeg), std::cos(t * kDeg));
            const auto p = truth.project(d), q = model.project(d);
            const double e = p && q ? glm::length(*p - *q) : 1e9;
            sum += e;
            worst = std::max(worst, e);
            if (covariance) sumStd += projectionStdPx(model, *covariance, {d.x, d.y, d.z});
            ++n;
        }
    meanPx = sum / n;
    maxPx = worst;
    if (stated) *stated = sumStd / n;
}

}  // namespace

const char* fisheyeLensName(FisheyeLens lens) {
    return lens == FisheyeLens::Equisolid ? "equisolid" : "equidistant";
}

FisheyeDraw runFisheyeDraw(unsigned seed, const FisheyeDrawOptions& o) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    FisheyeDraw r;
    r.seed = seed;
    r.lens = seed % 2 ? FisheyeLens::Equisolid : FisheyeLens::Equidistant;
    r.fovDeg = o.minFovDeg + (o.maxFovDeg - o.minFovDeg) * uni(rng);
    r.blurPx = o.minBlurPx + (o.maxBlurPx - o.minBlurPx) * uni(rng);
    r.noiseLevels = o.minNoise + (o.maxNoise - o.minNoise) * uni(rng);
    const CameraIntrinsics truth = idealFisheye(r.lens, r.fovDeg, o.width, o.height);
    const ChessboardGeometry board{9, 6, 0.025};
    const auto target = CalibrationTarget::chessboard(board);
    const auto poses = drawPoses(truth, board, o.views, rng);
    const ChessboardRenderer renderer(truth, o.supersample);
    std::vector<CalibrationView> views;
    for (size_t i = 0; i < poses.size(); ++i) {
        cv::Mat img = blurInLinearLight(renderer.render(board, poses[i]), r.blurPx);
        // Noise from a generator of this draw and view (not cv::theRNG, whose state depends on
        // what ran before), so a seed gives the same draw in the benchmark and the test.
        cv::Mat noise(img.size(), CV_32F);
        cv::RNG noiseRng(uint64_t(seed) * 1000003u + i);
        noiseRng.fill(noise, cv::RNG::NORMAL, 0.0, r.noiseLevels);
        cv::Mat noisy;
        img.convertTo(noisy, CV_32F);
        noisy += noise;
        noisy.convertTo(img, CV_8U);
        ++r.viewsRendered;
        const auto d = target.detect(img, "view" + std::to_string(i));
        if (!d.found) continue;
        ++r.viewsDetected;
        if (d.view.detector == "sector-based") ++r.fallbackViews;
        views.push_back(d.view);
    }
    CalibrationOptions co;
    co.model = DistortionModel::KannalaBrandt;
    try {
        const auto result = calibrate(views, {o.width, o.height}, co);
        r.viewsUsed = result.usedViewCount();
        r.droppedCorners = result.droppedCornerCount;
        r.reachDeg = result.calibration.reachDeg;
        r.reliable = result.calibration.reliable;
        compare(truth, result.calibration.intrinsics, o.compareUpToDeg, r.mirageMeanPx,
                r.mirageMaxPx, &result.intrinsicCovariance, &r.statedStdPx);
    } catch (const Error& e) {
        r.error = e.what();
        r.mirageMeanPx = r.mirageMaxPx = r.statedStdPx = std::numeric_limits<double>::quiet_NaN();
    }
    // OpenCV on the same detected corners.
    r.opencvMeanPx = std::numeric_limits<double>::quiet_NaN();
    try {
        std::vector<std::vector<cv::Point3d>> obj;
        std::vector<std::vector<cv::Point2d>> img;
        for (const auto& v : views) {
            obj.emplace_back(v.boardPoints.begin(), v.boardPoints.end());
            img.emplace_back(v.imagePoints.begin(), v.imagePoints.end());
        }
        cv::Matx33d K;
        cv::Vec4d D;
        std::vector<cv::Vec3d> rv, tv;
        cv::fisheye::calibrate(
            obj, img, {o.width, o.height}, K, D, rv, tv,
            cv::fisheye::CALIB_RECOMPUTE_EXTRINSIC | cv::fisheye::CALIB_FIX_SKEW,
            cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-10));
        CameraIntrinsics cvModel = truth;
        cvModel.fx = K(0, 0);
        cvModel.fy = K(1, 1);
        cvModel.cx = K(0, 2);
        cvModel.cy = K(1, 2);
        cvModel.distortion = {D[0], D[1], D[2], D[3]};
        double maxPx = 0;
        compare(truth, cvModel, o.compareUpToDeg, r.opencvMeanPx, maxPx);
    } catch (const cv::Exception&) {
        // cv::fisheye fails on some sets ("fabs(norm_u1) > 0"): no OpenCV figure for this draw.
    }
    return r;
}

}  // namespace mirage::calib
