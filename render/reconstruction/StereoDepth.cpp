#include "render/reconstruction/StereoDepth.h"

#include <algorithm>
#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"

namespace mirage::reconstruction {
namespace {

cv::Mat cameraMatrix(const CameraIntrinsics& k) {
    return (cv::Mat_<double>(3, 3) << k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
}

cv::Mat distortion(const CameraIntrinsics& k) {
    cv::Mat d(1, 5, CV_64F);
    for (int i = 0; i < 5; ++i) d.at<double>(i) = k.coeff(size_t(i));
    return d;
}

cv::Mat toCv(const glm::dmat3& m) {
    cv::Mat r(3, 3, CV_64F);
    for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col) r.at<double>(row, col) = m[col][row];
    return r;
}

glm::dmat3 toGlm(const cv::Mat& r) {
    glm::dmat3 m;
    for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col) m[col][row] = r.at<double>(row, col);
    return m;
}

// Is frame b a usable stereo partner of frame a? Returns the baseline (metres), or a negative
// value when not: too short or long, optical axes too far apart, or a baseline that runs along
// the viewing direction or the image's vertical (SGBM matches along rows only).
double partnerBaseline(const PosedFrame& a, const PosedFrame& b, const StereoOptions& o) {
    const glm::dvec3 centreInA = a.T_world_camera.inverse() * b.T_world_camera.translation;
    const double baseline = glm::length(centreInA);
    if (baseline < o.minBaselineM || baseline > o.maxBaselineM) return -1;
    const glm::dvec3 axisA = a.T_world_camera.rotationMatrix()[2];
    const glm::dvec3 axisB = b.T_world_camera.rotationMatrix()[2];
    if (glm::degrees(std::acos(std::clamp(glm::dot(axisA, axisB), -1.0, 1.0))) > o.maxViewAngleDeg)
        return -1;
    const glm::dvec3 dir = centreInA / baseline;
    if (std::abs(dir.x) < std::max(std::abs(dir.y), std::abs(dir.z))) return -1;
    return baseline;
}

// Validity of each rectified pixel: inside the original image.
cv::Mat rectifiedCoverage(const cv::Mat& mapX, const cv::Mat& mapY, cv::Size size) {
    cv::Mat ones(size, CV_8U, cv::Scalar(255)), covered;
    cv::remap(ones, covered, mapX, mapY, cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
    cv::erode(covered, covered, cv::Mat(), cv::Point(-1, -1), 2);
    return covered;
}

DepthView matchPair(const Footage& footage, const PosedFrame& left, const PosedFrame& right,
                    const StereoOptions& o) {
    const CameraIntrinsics& cam = footage.camera;
    const cv::Size size(cam.width, cam.height);
    const cv::Mat K = cameraMatrix(cam), D = distortion(cam);
    // x_right = R x_left + T.
    const Pose T_right_left = right.T_world_camera.inverse() * left.T_world_camera;
    cv::Mat R = toCv(T_right_left.rotationMatrix());
    cv::Mat T = (cv::Mat_<double>(3, 1) << T_right_left.translation.x, T_right_left.translation.y,
                 T_right_left.translation.z);
    cv::Mat R1, R2, P1, P2, Q;
    cv::stereoRectify(K, D, K, D, size, R, T, R1, R2, P1, P2, Q, cv::CALIB_ZERO_DISPARITY, 0.0,
                      size);
    cv::Mat map1x, map1y, map2x, map2y;
    cv::initUndistortRectifyMap(K, D, R1, P1, size, CV_32FC1, map1x, map1y);
    cv::initUndistortRectifyMap(K, D, R2, P2, size, CV_32FC1, map2x, map2y);
    DepthView v;
    v.frame = left.index;
    v.partner = right.index;
    cv::Mat rightRect;
    cv::remap(left.bgr, v.bgr, map1x, map1y, cv::INTER_LINEAR);
    cv::remap(right.bgr, rightRect, map2x, map2y, cv::INTER_LINEAR);
    v.fx = P1.at<double>(0, 0);
    v.fy = P1.at<double>(1, 1);
    v.cx = P1.at<double>(0, 2);
    v.cy = P1.at<double>(1, 2);
    v.baselineM = -P2.at<double>(0, 3) / P2.at<double>(0, 0);
    // p_rect = R1 p_left, so T_world_rect = T_world_left * (R1^T, 0).
    v.T_world_camera =
        left.T_world_camera * Pose::fromRotationTranslation(glm::transpose(toGlm(R1)), {});
    v.depth = cv::Mat(size, CV_32F, cv::Scalar(0));
    if (v.baselineM <= 0) return v;  // not a left-right pair after rectification

    // The disparities the working volume can have: from 0.6x to 2x the board's distance (objects
    // on the table up to about half the camera's height above it; the table's far side).
    const double boardDepth = std::max(0.05, (v.T_world_camera.inverse() * footage.board.point).z);
    const double zNear = std::max(o.minDepthM, 0.6 * boardDepth);
    const double zFar = std::min(o.maxDepthM, 2.0 * boardDepth);
    const double fb = v.fx * v.baselineM;
    const int minDisparity = std::max(0, int(std::floor(fb / zFar)));
    int numDisparities = int(std::ceil(fb / zNear)) - minDisparity;
    numDisparities = std::clamp((numDisparities + 15) / 16 * 16, 16, 256);
    const int channels = v.bgr.channels();
    const int b = o.blockSize;
    // P2 (the cost of a disparity jump) high: plain faces take the depth of their edges.
    auto sgbm = cv::StereoSGBM::create(minDisparity, numDisparities, b, 8 * channels * b * b,
                                       o.smoothness * channels * b * b, 1, 0, o.uniquenessRatio,
                                       100, 2, cv::StereoSGBM::MODE_HH);
    // A light blur first: sensor (and render) noise is not texture the two views share.
    cv::Mat leftSmooth, rightSmooth, disparity;
    cv::GaussianBlur(v.bgr, leftSmooth, {3, 3}, 0.8);
    cv::GaussianBlur(rightRect, rightSmooth, {3, 3}, 0.8);
    sgbm->compute(leftSmooth, rightSmooth, disparity);
    const cv::Mat coveredLeft = rectifiedCoverage(map1x, map1y, size);
    int valid = 0;
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            const short d16 = disparity.at<short>(y, x);
            if (d16 <= minDisparity * 16 || !coveredLeft.at<uchar>(y, x)) continue;
            const double z = fb / (d16 / 16.0);
            if (z < zNear || z > zFar) continue;
            v.depth.at<float>(y, x) = float(z);
            ++valid;
        }
    v.validFraction = double(valid) / double(size.area());
    return v;
}

// Geometric consistency between the depth maps: a depth is kept only when at least `minAgree`
// other maps see the same point within `tolerance` (metres, plus `depthFraction` of the depth)
// where it projects into them. One pair's wrong match (a plain face, repeated texture) seldom
// agrees with another pair's; surfaces seen by several pairs do.
void keepConsistentDepth(std::vector<DepthView>& views, int minAgree, double tolerance,
                         double depthFraction) {
    std::vector<cv::Mat> kept;
    for (size_t i = 0; i < views.size(); ++i) {
        const DepthView& v = views[i];
        cv::Mat out = v.depth.clone();
        int valid = 0;
        for (int y = 0; y < out.rows; ++y)
            for (int x = 0; x < out.cols; ++x) {
                float& z = out.at<float>(y, x);
                if (z <= 0) continue;
                const glm::dvec3 world =
                    v.T_world_camera * glm::dvec3((x - v.cx) / v.fx * z, (y - v.cy) / v.fy * z, z);
                int agree = 0;
                for (size_t j = 0; j < views.size() && agree < minAgree; ++j) {
                    if (j == i) continue;
                    const DepthView& w = views[j];
                    const glm::dvec3 c = w.T_world_camera.inverse() * world;
                    if (c.z <= 0) continue;
                    const int u = int(std::lround(w.fx * c.x / c.z + w.cx));
                    const int r = int(std::lround(w.fy * c.y / c.z + w.cy));
                    if (u < 0 || r < 0 || u >= w.depth.cols || r >= w.depth.rows) continue;
                    const float zw = w.depth.at<float>(r, u);
                    if (zw > 0 && std::abs(zw - c.z) < tolerance + depthFraction * c.z) ++agree;
                }
                if (agree < minAgree)
                    z = 0;
                else
                    ++valid;
            }
        kept.push_back(out);
        views[i].validFraction = double(valid) / double(out.total());
    }
    for (size_t i = 0; i < views.size(); ++i) views[i].depth = kept[i];
}

}  // namespace

std::vector<std::pair<int, int>> chooseStereoPairs(const Footage& footage, const StereoOptions& o) {
    std::vector<std::pair<int, int>> pairs;
    const int n = int(footage.frames.size());
    const int partners = std::max(1, o.partnersPerFrame);
    for (int i = 0; i < n; ++i) {
        std::vector<std::pair<double, int>> candidates;  // (baseline, frame)
        for (int j = 0; j < n; ++j) {
            if (j == i) continue;
            const double b =
                partnerBaseline(footage.frames[size_t(i)], footage.frames[size_t(j)], o);
            if (b >= 0) candidates.emplace_back(b, j);
        }
        // The k-th partner is the candidate nearest (1 + k/2) x the preferred baseline.
        for (int k = 0; k < partners && !candidates.empty(); ++k) {
            const double wanted = o.preferredBaselineM * (1.0 + 0.5 * k);
            auto best = std::min_element(
                candidates.begin(), candidates.end(), [&](const auto& a, const auto& b) {
                    return std::abs(a.first - wanted) < std::abs(b.first - wanted);
                });
            const int j = best->second;
            candidates.erase(best);
            const bool repeated =
                std::find(pairs.begin(), pairs.end(), std::make_pair(j, i)) != pairs.end() ||
                std::find(pairs.begin(), pairs.end(), std::make_pair(i, j)) != pairs.end();
            if (!repeated) pairs.emplace_back(i, j);
        }
    }
    if (int(pairs.size()) > o.maxPairs) {  // spread the kept pairs over the footage
        std::vector<std::pair<int, int>> kept;
        for (int k = 0; k < o.maxPairs; ++k)
            kept.push_back(pairs[size_t(k) * pairs.size() / size_t(o.maxPairs)]);
        pairs = kept;
    }
    return pairs;
}

std::vector<DepthView> computeDepthViews(const Footage& footage, const StereoOptions& o,
                                         const std::function<void(int, int)>& progress) {
    if (footage.camera.model != DistortionModel::BrownConrady)
        throw Error(
            "reconstruction: the main camera has a fish-eye calibration; dense stereo needs a "
            "pinhole (Brown-Conrady) main camera");
    const auto pairs = chooseStereoPairs(footage, o);
    std::vector<DepthView> views;
    int done = 0;
    for (const auto& [i, j] : pairs) {
        const PosedFrame& a = footage.frames[size_t(i)];
        const PosedFrame& b = footage.frames[size_t(j)];
        // The left image is the one whose partner lies to its right (+X of its camera).
        const bool aLeft = (a.T_world_camera.inverse() * b.T_world_camera.translation).x > 0;
        DepthView v = aLeft ? matchPair(footage, a, b, o) : matchPair(footage, b, a, o);
        if (v.validFraction > 0) views.push_back(std::move(v));
        if (progress) progress(++done, int(pairs.size()));
    }
    if (o.minAgreeingMaps > 0)
        keepConsistentDepth(views, o.minAgreeingMaps, o.agreementM, o.agreementDepthFraction);
    return views;
}

}  // namespace mirage::reconstruction
