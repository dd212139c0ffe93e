#include "tracking/FeatureTracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "core/math/LevenbergMarquardt.h"

namespace mirage::tracking {
namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The pose perturbed by x = (rotation vector in world axes, camera-centre offset in metres): the
// step convention of the tag pose (PoseEstimator.h, poseLeastSquares).
Pose perturbed(const Pose& p, const double* x) {
    const glm::dvec3 w(x[0], x[1], x[2]);
    const double a = glm::length(w);
    Pose q = p;
    if (a > 0) q.rotation = glm::normalize(glm::angleAxis(a, w / a) * p.rotation);
    q.translation += glm::dvec3(x[3], x[4], x[5]);
    return q;
}

// One observed point for the pose: h(c) = rho (anchor - c) + direction seen at `pixel`, its
// residual whitened by W (2x2, row-major: r_w = W (projection - pixel)). A tag corner is a point
// with rho = 1, anchor = the corner, direction = 0.
struct PosePoint {
    glm::dvec3 anchor, direction;
    double rho;
    glm::dvec2 pixel;
    glm::dmat2 W;
};

// Residuals (2 per point, whitened) and their Jacobian w.r.t. the step (w, c):
// X_c = R^T h, dX_c/dw = R^T [h]_x, dX_c/dc = -rho R^T.
bool pointResiduals(const CameraIntrinsics& cam, const Pose& T, const std::vector<PosePoint>& pts,
                    std::vector<double>& r, std::vector<double>* J) {
    r.assign(pts.size() * 2, 0.0);
    if (J) J->assign(pts.size() * 12, 0.0);
    const glm::dmat3 Rt = glm::transpose(T.rotationMatrix());
    for (size_t i = 0; i < pts.size(); ++i) {
        const PosePoint& p = pts[i];
        const glm::dvec3 h = p.rho * (p.anchor - T.translation) + p.direction;
        glm::dmat3x2 dp;
        const auto px = cam.projectWithJacobian(Rt * h, dp);
        if (!px) return false;  // behind the camera: not an admissible pose
        const glm::dvec2 rw = p.W * (*px - p.pixel);
        r[2 * i] = rw.x;
        r[2 * i + 1] = rw.y;
        if (!J) continue;
        const glm::dmat3 skew(0, h.z, -h.y, -h.z, 0, h.x, h.y, -h.x, 0);
        const glm::dmat3 dXdw = Rt * skew;
        const glm::dmat3 dXdc = -p.rho * Rt;
        for (int j = 0; j < 6; ++j) {
            const glm::dvec2 g = p.W * (dp * (j < 3 ? dXdw[j] : dXdc[j - 3]));
            (*J)[(2 * i) * 6 + size_t(j)] = g.x;
            (*J)[(2 * i + 1) * 6 + size_t(j)] = g.y;
        }
    }
    return true;
}

lm::Problem poseProblem(const CameraIntrinsics& cam, const std::vector<PosePoint>& pts,
                        const CentrePrior& prior) {
    lm::Problem p;
    p.parameters = 6;
    p.residuals = [&cam, &pts, &prior](const std::vector<double>& x, std::vector<double>& r) {
        const Pose T = poseOfState(x);
        if (!pointResiduals(cam, T, pts, r, nullptr)) return false;
        if (prior.active) {
            const glm::dvec3 rc = prior.W * (T.translation - prior.centre);
            r.insert(r.end(), {rc.x, rc.y, rc.z});
        }
        return true;
    };
    p.jacobian = [&cam, &pts, &prior](const std::vector<double>& x, lm::JacobianSink& sink) {
        std::vector<double> r, J;
        pointResiduals(cam, poseOfState(x), pts, r, &J);
        static const std::vector<int> kColumns = {0, 1, 2, 3, 4, 5};
        sink.add(0, J.size() / 6, kColumns, J.data());
        if (prior.active) {
            // The step moves the centre by dx[3..5] (perturbed): dr/dc = W.
            static const std::vector<int> kCentre = {3, 4, 5};
            double Jc[9];
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) Jc[i * 3 + j] = prior.W[j][i];
            sink.add(pts.size() * 2, 3, kCentre, Jc);
        }
    };
    p.retract = [](std::vector<double>& x, const std::vector<double>& dx) {
        x = poseState(perturbed(poseOfState(x), dx.data()));
    };
    return p;
}

// L^-1 of the Cholesky factor of a symmetric positive 3x3 matrix (glm, column-major); false when
// the matrix is not positive definite.
bool inverseCholesky(const glm::dmat3& S, glm::dmat3& W) {
    double L[3][3] = {};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j <= i; ++j) {
            double v = S[j][i];
            for (int k = 0; k < j; ++k) v -= L[i][k] * L[j][k];
            if (i == j) {
                if (!(v > 0)) return false;
                L[i][i] = std::sqrt(v);
            } else {
                L[i][j] = v / L[j][j];
            }
        }
    double Li[3][3] = {};  // forward substitution of L Li = I
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < 3; ++i) {
            double v = i == c ? 1.0 : 0.0;
            for (int k = 0; k < i; ++k) v -= L[i][k] * Li[k][c];
            Li[i][c] = v / L[i][i];
        }
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) W[j][i] = Li[i][j];
    return true;
}

// Inverse square root of a symmetric positive 2x2 matrix (the whitening of a residual).
glm::dmat2 inverseSqrt(const glm::dmat2& S) {
    const double a = S[0][0], b = S[1][0], d = S[1][1];
    const double tr = a + d, det = std::max(1e-18, a * d - b * b);
    const double s = std::sqrt(det), t = std::sqrt(tr + 2 * s);
    // sqrt(S) = (S + s I) / t; its inverse.
    const glm::dmat2 root = (S + glm::dmat2(s)) / t;
    return glm::inverse(root);
}

}  // namespace

const char* trackingModeName(TrackingMode m) {
    switch (m) {
        case TrackingMode::Board:
            return "board";
        case TrackingMode::BoardAndFeatures:
            return "board+features";
        case TrackingMode::FeaturesOnly:
            return "features only";
    }
    return "board";
}

// A tracked feature with its landmark, as the pose sees it from the camera pose `at`.
struct FeatureTracker::Correspondence {
    const Landmark* landmark;
    glm::dvec2 pixel;
    PosePoint point;
    double depthM;  // along the ray from `at` (metres; 1e3 for rho = 0)
};

FeatureTracker::FeatureTracker(Board board, CameraIntrinsics camera, FeatureTrackingOptions options,
                               PoseEstimatorOptions bounds)
    : board_(std::move(board)), camera_(camera), options_(options), bounds_(bounds) {
    scale_ = std::max(0.25, camera_.width / 640.0);
}

void FeatureTracker::reset() {
    pyramid_.clear();
    previousGrey_.release();
    deferred_.reset();
    tracks_.clear();
    map_.clear();
    framesSinceDetect_ = 0;
    lastDetectionShort_ = false;
    mapCovariance_ = {};
    derivedCovariance_ = {};
    lastPoseCovariance_.reset();
}

std::vector<cv::Point2f> FeatureTracker::trackedPixels() const {
    std::vector<cv::Point2f> out;
    for (const auto& t : tracks_)
        if (t.landmark >= 0) out.push_back(t.px);
    return out;
}

std::vector<uchar> FeatureTracker::trackForwardBackward(const std::vector<cv::Mat>& from,
                                                        const std::vector<cv::Mat>& to, int win,
                                                        int levels,
                                                        const std::vector<cv::Point2f>& prev,
                                                        std::vector<cv::Point2f>& next) const {
    std::vector<uchar> status, statusBack;
    const cv::TermCriteria term(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                options_.kltMaxIterations, options_.kltEpsilonPx);
    // No error output: OpenCV then skips a pass over each window at the finest level.
    cv::calcOpticalFlowPyrLK(from, to, prev, next, status, cv::noArray(), cv::Size(win, win),
                             levels, term, cv::OPTFLOW_USE_INITIAL_FLOW);
    std::vector<cv::Point2f> back = prev;
    cv::calcOpticalFlowPyrLK(to, from, next, back, statusBack, cv::noArray(), cv::Size(win, win),
                             std::clamp(options_.backwardLevels, 0, options_.kltLevels), term,
                             cv::OPTFLOW_USE_INITIAL_FLOW);
    const int cols = to.front().cols, rows = to.front().rows;
    const float border = 2.0f;
    std::vector<uchar> good(prev.size(), 0);
    for (size_t i = 0; i < prev.size(); ++i) {
        const bool inside = next[i].x >= border && next[i].y >= border &&
                            next[i].x < float(cols) - border && next[i].y < float(rows) - border;
        const double fb = cv::norm(back[i] - prev[i]);
        good[i] = status[i] && statusBack[i] && inside &&
                  fb <= options_.forwardBackwardMaxPx * std::max(1.0, scale_);
    }
    return good;
}

void FeatureTracker::track(const cv::Mat& grey, const std::optional<Pose>& predicted) {
    stats_ = {};
    const auto t0 = std::chrono::steady_clock::now();
    const int win = std::max(9, int(std::lround(options_.kltWindowPx * scale_))) | 1;
    // The previous frame's detection, deferred until a frame follows it within the gap.
    if (deferred_ && predicted && !previousGrey_.empty()) {
        detect(previousGrey_, deferred_->pose, deferred_->derived, deferred_->boardPixels);
        framesSinceDetect_ = 0;
    }
    deferred_.reset();
    if (!tracks_.empty() && pyramid_.empty() && !previousGrey_.empty())
        cv::buildOpticalFlowPyramid(previousGrey_, pyramid_, cv::Size(win, win),
                                    options_.kltLevels);
    std::vector<cv::Mat> pyramid;
    if (!pyramid_.empty() && !tracks_.empty()) {
        cv::buildOpticalFlowPyramid(grey, pyramid, cv::Size(win, win), options_.kltLevels);
        std::vector<cv::Point2f> prev, next;
        for (const auto& t : tracks_) prev.push_back(t.px);
        // Where the predicted pose puts each landmark starts its search (a fast pan moves the
        // image by more than the pyramid reaches from the old position).
        next = prev;
        if (predicted) {
            const glm::dmat3 Rt = glm::transpose(predicted->rotationMatrix());
            for (size_t i = 0; i < tracks_.size(); ++i) {
                const Landmark* l =
                    tracks_[i].landmark >= 0 ? map_.find(tracks_[i].landmark) : nullptr;
                if (!l) continue;
                const auto px = camera_.project(Rt * l->homogeneous(predicted->translation));
                if (px && px->x > -0.5 * grey.cols && px->x < 1.5 * grey.cols &&
                    px->y > -0.5 * grey.rows && px->y < 1.5 * grey.rows)
                    next[i] = cv::Point2f(float(px->x), float(px->y));
            }
        }
        // The predicted start is usually within a few pixels: a first pass over the lower
        // levels only; the tracks it loses (a motion the prediction missed) search again over
        // every level from the same start.
        std::vector<cv::Point2f> start = next;
        const int levels = options_.kltLevels;
        const int first = predicted && options_.kltFirstLevels > 0
                              ? std::min(options_.kltFirstLevels, levels)
                              : levels;
        std::vector<uchar> good = trackForwardBackward(pyramid_, pyramid, win, first, prev, next);
        if (first < levels) {
            std::vector<size_t> again;
            std::vector<cv::Point2f> prevAgain, nextAgain;
            for (size_t i = 0; i < good.size(); ++i)
                if (!good[i]) {
                    again.push_back(i);
                    prevAgain.push_back(prev[i]);
                    nextAgain.push_back(start[i]);
                }
            if (!again.empty()) {
                const std::vector<uchar> goodAgain =
                    trackForwardBackward(pyramid_, pyramid, win, levels, prevAgain, nextAgain);
                for (size_t k = 0; k < again.size(); ++k) {
                    good[again[k]] = goodAgain[k];
                    next[again[k]] = nextAgain[k];
                }
            }
        }
        std::vector<Track> kept;
        for (size_t i = 0; i < tracks_.size(); ++i) {
            if (good[i])
                kept.push_back({next[i], tracks_[i].landmark});
            else if (tracks_[i].landmark >= 0)
                map_.remove(tracks_[i].landmark);  // the map holds only what is tracked
        }
        tracks_ = std::move(kept);
    } else {
        for (const auto& t : tracks_)
            if (t.landmark >= 0) map_.remove(t.landmark);
        tracks_.clear();
    }
    // Without tracks no pyramid was built; the image is kept for a deferred detection.
    pyramid_ = std::move(pyramid);
    if (pyramid_.empty())
        grey.copyTo(previousGrey_);
    else
        previousGrey_.release();
    stats_.tracked = int(tracks_.size());
    stats_.trackMs = msSince(t0);
}

void FeatureTracker::learn(const cv::Mat& grey, const PoseEstimate& pose, bool fromBoard,
                           const cv::Rect& boardPixels) {
    if (!pose.pose) return;
    const auto t0 = std::chrono::steady_clock::now();
    const Pose& T = *pose.pose;
    lastPoseCovariance_ = pose.covariance;
    lastCentre_ = T.translation;
    const double rotSigma = glm::radians(pose.sigmaRotDeg());
    const double f = 0.5 * (camera_.fx + camera_.fy);
    if (fromBoard) {
        // The map's shared error: a running mean of the board poses' covariances.
        for (size_t k = 0; k < 36; ++k)
            mapCovariance_[k] = mapCovariance_[k] == 0 && k % 7 == 0
                                    ? pose.covariance[k]
                                    : 0.8 * mapCovariance_[k] + 0.2 * pose.covariance[k];
    }
    // Every track must stay where its landmark says it is under the pose (else: a moving
    // object, a track that slid); at a board pose the agreeing ones refine their landmarks.
    const double sigmaPx = std::hypot(options_.featureSigmaPx * scale_, f * rotSigma);
    const double minTurn = glm::radians(options_.minTurnDeg);
    const glm::dmat3 Rt = glm::transpose(T.rotationMatrix());
    std::vector<Track> kept;
    for (const auto& t : tracks_) {
        Landmark* l = t.landmark >= 0 ? map_.find(t.landmark) : nullptr;
        if (!l) continue;
        bool agrees = false;
        const glm::dvec3 h = l->homogeneous(T.translation);
        glm::dmat3x2 dp;
        if (const auto px = camera_.projectWithJacobian(Rt * h, dp)) {
            const glm::dvec3 dh[3] = {l->e1, l->e2, l->anchor - T.translation};
            glm::dvec2 J[3];
            for (int k = 0; k < 3; ++k) J[k] = dp * (Rt * dh[k]);
            glm::dmat2 S(sigmaPx * sigmaPx);
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b)
                    S += l->covariance[size_t(a * 3 + b)] * glm::outerProduct(J[a], J[b]);
            const glm::dvec2 r = *px - glm::dvec2(t.px.x, t.px.y);
            agrees = glm::dot(r, glm::inverse(S) * r) <= options_.maxLandmarkChi2;
        }
        if (agrees && fromBoard) {
            map_.observe(t.landmark, camera_, {T, glm::dvec2(t.px.x, t.px.y), sigmaPx},
                         options_.minBaselineM, minTurn);
            l = map_.find(t.landmark);
        }
        if (!agrees || l->rmsPx > options_.maxLandmarkRmsPx * std::max(1.0, scale_)) {
            map_.remove(t.landmark);
            continue;
        }
        kept.push_back(t);
    }
    tracks_ = std::move(kept);
    const int maxFeatures = int(options_.maxFeatures * scale_);
    if (options_.enabled && (fromBoard || options_.derivedLandmarks) &&
        (++framesSinceDetect_ >= options_.detectEvery ||
         (!lastDetectionShort_ &&
          double(tracks_.size()) < options_.refillFraction * maxFeatures))) {
        // Nothing was tracked into this frame: detect only if a next frame follows.
        if (pyramid_.empty())
            deferred_ = DeferredDetection{pose, !fromBoard, boardPixels};
        else
            detect(grey, pose, !fromBoard, boardPixels);
        framesSinceDetect_ = 0;
    }
    stats_.mapMs = msSince(t0);
}

void FeatureTracker::detect(const cv::Mat& grey, const PoseEstimate& pose, bool derived,
                            const cv::Rect& boardPixels) {
    const int maxFeatures = int(options_.maxFeatures * scale_);
    const int want = maxFeatures - int(tracks_.size());
    if (want <= 0) return;
    const double minDist = options_.minDistancePx * scale_;
    cv::Mat mask(grey.size(), CV_8U, cv::Scalar(255));
    mask(boardPixels & cv::Rect(0, 0, grey.cols, grey.rows)).setTo(0);
    for (const auto& t : tracks_) cv::circle(mask, t.px, int(minDist), cv::Scalar(0), -1);
    std::vector<cv::Point2f> corners;
    cv::goodFeaturesToTrack(grey, corners, want, options_.cornerQuality, minDist, mask, 3);
    lastDetectionShort_ = int(corners.size()) < want;
    stats_.detected = 0;
    if (corners.empty()) return;
    const cv::TermCriteria term(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 10, 0.03);
    cv::cornerSubPix(grey, corners, cv::Size(3, 3), cv::Size(-1, -1), term);
    const double rotSigma = glm::radians(pose.sigmaRotDeg());
    const double depth = pose.distanceM > 0 ? pose.distanceM : 0.5;
    // A derived landmark's share of its pose's error is common to all landmarks made from that
    // pose: added once to every later pose from them (derivedCovariance_), not per landmark.
    if (derived) derivedCovariance_ = pose.covariance;
    for (const auto& c : corners) {
        const int id = map_.add(camera_, *pose.pose, {c.x, c.y}, options_.featureSigmaPx * scale_,
                                derived ? 0.0 : rotSigma, derived ? 0.0 : pose.sigmaPosM(), depth,
                                options_.rhoSigmaFraction, derived);
        if (id >= 0) {
            tracks_.push_back({c, id});
            ++stats_.detected;
        }
    }
}

std::vector<FeatureTracker::Correspondence> FeatureTracker::correspondences(const Pose& at) const {
    std::vector<Correspondence> out;
    const glm::dmat3 Rt = glm::transpose(at.rotationMatrix());
    const double sigma = options_.featureSigmaPx * scale_;
    for (const auto& t : tracks_) {
        const Landmark* l =
            t.landmark >= 0 ? const_cast<LandmarkMap&>(map_).find(t.landmark) : nullptr;
        if (!l) continue;
        const glm::dvec3 h = l->homogeneous(at.translation);
        glm::dmat3x2 dp;
        const auto px = camera_.projectWithJacobian(Rt * h, dp);
        if (!px) continue;
        // The landmark's uncertainty seen from `at`: its three parameters and its anchor.
        const glm::dvec3 dh[3] = {l->e1, l->e2, l->anchor - at.translation};
        glm::dvec2 J[3];
        for (int k = 0; k < 3; ++k) J[k] = dp * (Rt * dh[k]);
        glm::dmat2 S(sigma * sigma);
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                S += l->covariance[size_t(a * 3 + b)] * glm::outerProduct(J[a], J[b]);
        const double anchorPx = l->rho * l->anchorSigmaM * 0.5 * (camera_.fx + camera_.fy) /
                                std::max(1e-6, glm::length(Rt * h));
        S += glm::dmat2(anchorPx * anchorPx);
        Correspondence c;
        c.landmark = l;
        c.pixel = {t.px.x, t.px.y};
        c.point = {l->anchor, l->direction, l->rho, c.pixel, inverseSqrt(S)};
        c.depthM = l->rho > 1e-3 ? glm::length(h) / l->rho : 1e3;
        out.push_back(c);
    }
    return out;
}

namespace {

// T_world_camera from OpenCV's rvec / tvec (T_camera_world).
Pose poseFromRvecTvec(const cv::Mat& rvec, const cv::Mat& tvec) {
    cv::Mat R;
    cv::Rodrigues(rvec, R);
    glm::dmat3 r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r[j][i] = R.at<double>(i, j);
    const glm::dvec3 t(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
    return Pose::fromRotationTranslation(r, t).inverse();
}

double chi2At(const CameraIntrinsics& cam, const Pose& T, const PosePoint& p) {
    std::vector<double> r;
    if (!pointResiduals(cam, T, {p}, r, nullptr)) return 1e18;
    return r[0] * r[0] + r[1] * r[1];
}

}  // namespace

PoseEstimate FeatureTracker::estimate(const Pose& predicted, const std::vector<TagDetection>& tags,
                                      double sinceLastPoseS, const glm::dvec3& velocity) {
    const auto t0 = std::chrono::steady_clock::now();
    const CentrePrior prior = centrePrior(sinceLastPoseS, velocity);
    PoseEstimate e;
    e.state = TrackingState::Lost;
    const std::vector<Correspondence> corr = correspondences(predicted);
    stats_.landmarks = int(corr.size());
    // The board tags still seen: their corners are exact world points.
    std::vector<PosePoint> tagPoints;
    std::vector<int> tagIds;
    const glm::dmat2 tagW(1.0 / (options_.tagCornerSigmaPx * scale_));
    for (const auto& d : tags) {
        const BoardTag* bt = board_.find(d.id);
        if (!bt || std::find(tagIds.begin(), tagIds.end(), d.id) != tagIds.end()) continue;
        const auto world = bt->cornersInWorld();
        for (size_t k = 0; k < 4; ++k)
            tagPoints.push_back({world[k], glm::dvec3(0.0), 1.0, d.corners[k], tagW});
        tagIds.push_back(d.id);
    }
    if (corr.size() < size_t(std::max(4, options_.minInliers / 2))) {
        e.reason = "features: " + std::to_string(corr.size()) + " landmarks tracked (too few)";
        stats_.poseMs = msSince(t0);
        return e;
    }
    // Start poses: the prediction, and RANSAC over the landmarks' point estimates.
    std::vector<Pose> starts = {predicted};
    if (auto start = ransacStart(corr)) starts.push_back(*start);
    auto inliersAt = [&](const Pose& T) {
        std::vector<size_t> in;
        for (size_t i = 0; i < corr.size(); ++i)
            if (chi2At(camera_, T, corr[i].point) <= options_.inlierChi2) in.push_back(i);
        return in;
    };
    Pose best = predicted;
    std::vector<size_t> inliers;
    for (const Pose& s : starts) {
        auto in = inliersAt(s);
        if (in.size() > inliers.size()) inliers = std::move(in), best = s;
    }
    // Levenberg-Marquardt over the inliers and the tags; inliers chosen again at its pose.
    std::vector<PosePoint> pts;
    std::vector<double> x = poseState(best);
    lm::Report report;
    lm::Options o;
    o.maxIterations = 20;
    o.relativeTolerance = 1e-8;
    for (int round = 0; round < 2; ++round) {
        pts.clear();
        for (size_t i : inliers) pts.push_back(corr[i].point);
        pts.insert(pts.end(), tagPoints.begin(), tagPoints.end());
        if (pts.size() < 4) break;
        const lm::Problem problem = poseProblem(camera_, pts, prior);
        report = lm::solve(problem, x, o);
        inliers = inliersAt(poseOfState(x));
    }
    stats_.inliers = int(inliers.size());
    stats_.tags = int(tagIds.size());
    pts.clear();
    for (size_t i : inliers) pts.push_back(corr[i].point);
    pts.insert(pts.end(), tagPoints.begin(), tagPoints.end());
    const Pose T = poseOfState(x);
    if (!T.isFinite() || pts.size() < 4) {
        e.reason = "features: no pose from " + std::to_string(corr.size()) + " landmarks";
        stats_.poseMs = msSince(t0);
        return e;
    }
    e.pose = T;
    e.tagsUsed = tagIds;
    const lm::Problem problem = poseProblem(camera_, pts, prior);
    const lm::Covariance cov = lm::covariance(problem, x);
    std::vector<double> r;
    pointResiduals(camera_, T, pts, r, nullptr);
    double whitened = 0;
    for (double v : r) whitened += v * v;
    const double whitenedRms = std::sqrt(whitened / double(std::max<size_t>(1, r.size())));
    // Unwhitened pixel RMS of the landmark inliers, and their spread and depth.
    double px2 = 0;
    double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;  // the inliers' image box
    std::vector<double> depths;
    int derived = 0;
    for (size_t k = 0; k < inliers.size(); ++k) {
        const auto& c = corr[inliers[k]];
        PosePoint p = c.point;
        p.W = glm::dmat2(1.0);
        px2 += chi2At(camera_, T, p);
        x0 = std::min(x0, c.pixel.x), x1 = std::max(x1, c.pixel.x);
        y0 = std::min(y0, c.pixel.y), y1 = std::max(y1, c.pixel.y);
        depths.push_back(c.depthM);
        derived += c.landmark->derived;
    }
    e.rmsPx = inliers.empty() ? 0 : std::sqrt(px2 / double(inliers.size()));
    if (!depths.empty()) {
        std::nth_element(depths.begin(), depths.begin() + long(depths.size() / 2), depths.end());
        e.distanceM = std::min(depths[depths.size() / 2], 50.0);
    }
    if (!tagIds.empty()) {
        glm::dvec3 centre(0.0);
        for (int id : tagIds) centre += board_.find(id)->T_world_tag.translation;
        const double tagDistance = glm::length(centre / double(tagIds.size()) - T.translation);
        e.distanceM = depths.empty() ? tagDistance : std::min(e.distanceM, tagDistance);
    }
    // Covariance: the fit's (with whitened residuals the variance factor is 1 when the noise
    // model holds; more if the residuals say so), plus the map's shared error.
    if (cov.ok) {
        const double factor = std::max(1.0, cov.sigma2) / std::max(1e-300, cov.sigma2);
        const double fd = inliers.empty() ? 0 : double(derived) / double(inliers.size());
        for (size_t k = 0; k < 36; ++k)
            e.covariance[k] =
                cov.matrix[k] * factor + (1 - fd) * mapCovariance_[k] + fd * derivedCovariance_[k];
    }
    stats_.poseMs = msSince(t0);

    // The same bounds as for tags, after the consistency checks.
    const double spread =
        inliers.empty() ? 0.0 : (x1 - x0) * (y1 - y0) / (double(camera_.width) * camera_.height);
    judge(e, {inliers.size(), corr.size(), tagIds.size(), whitenedRms, spread, cov.ok,
              report.converged() || report.stop == lm::Stop::MaxIterations});
    return e;
}

CentrePrior FeatureTracker::centrePrior(double sinceLastPoseS, const glm::dvec3& velocity) const {
    CentrePrior prior;
    if (!(options_.centreAccelSigma > 0) || !(sinceLastPoseS > 0) || !lastPoseCovariance_)
        return prior;
    // The last pose's centre moved by the board poses' velocity; its error: the last pose's
    // plus an unmodelled acceleration over the gap (the second difference of the centre:
    // a dt^2).
    const double q = options_.centreAccelSigma * sinceLastPoseS * sinceLastPoseS;
    glm::dmat3 S(q * q);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) S[j][i] += (*lastPoseCovariance_)[size_t((3 + i) * 6 + 3 + j)];
    prior.active = inverseCholesky(S, prior.W);
    prior.centre = lastCentre_ + velocity * sinceLastPoseS;
    return prior;
}

std::optional<Pose> FeatureTracker::ransacStart(const std::vector<Correspondence>& corr) const {
    std::vector<cv::Point3d> obj;
    std::vector<cv::Point2d> img;
    for (const auto& c : corr) {
        const auto ray = camera_.unproject(c.pixel);
        if (!ray || ray->z <= 1e-3) continue;
        const glm::dvec3 X =
            c.landmark->anchor + c.landmark->direction / std::max(c.landmark->rho, 1e-3);
        obj.emplace_back(X.x, X.y, X.z);
        img.emplace_back(ray->x / ray->z, ray->y / ray->z);
    }
    cv::Mat rvec, tvec;
    std::vector<int> inl;
    const double f = 0.5 * (camera_.fx + camera_.fy);
    if (obj.size() >= 6 &&
        cv::solvePnPRansac(obj, img, cv::Mat::eye(3, 3, CV_64F), cv::noArray(), rvec, tvec, false,
                           options_.ransacIterations,
                           float(options_.ransacThresholdPx * scale_ / f), 0.99, inl,
                           cv::SOLVEPNP_AP3P) &&
        inl.size() >= 6)
        return poseFromRvecTvec(rvec, tvec);
    return std::nullopt;
}

void FeatureTracker::judge(PoseEstimate& e, const FitQuality& q) const {
    const double share = double(q.inliers) / double(std::max<size_t>(1, q.landmarks));
    const double sigmaRot = e.sigmaRotDeg(),
                 sigmaPosRel = e.sigmaPosM() / std::max(1e-6, e.distanceM);
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "features: %zu of %zu landmarks, %zu tags; whitened RMS %.2f, spread %.0f %%; "
                  "1 sigma %.3f deg, %.2f %% of the distance",
                  q.inliers, q.landmarks, q.tags, q.whitenedRms, 100 * q.spread, sigmaRot,
                  100 * sigmaPosRel);
    e.reason = buf;
    const bool enoughFeatures = int(q.inliers) >= options_.minInliers &&
                                share >= options_.minInlierFraction &&
                                q.spread >= options_.minSpreadFraction;
    // Tags alone may carry the pose (board+features) when the landmarks add too little.
    const bool enough =
        enoughFeatures || (q.tags >= 1 && q.inliers >= 6 && share >= options_.minInlierFraction);
    if (!q.covarianceOk || !q.converged) {
        e.state = TrackingState::Lost;
        e.reason += "; the fit did not converge";
    } else if (!enough) {
        e.state = TrackingState::Uncertain;
        e.reason += "; too few or too clustered inliers";
    } else if (q.whitenedRms > options_.maxWhitenedRms) {
        e.state = TrackingState::Uncertain;
        e.reason += "; residuals larger than the noise model";
    } else if (sigmaRot > bounds_.okMaxSigmaRotDeg || sigmaPosRel > bounds_.okMaxSigmaPosFraction) {
        e.state = TrackingState::Uncertain;
        e.reason += "; too uncertain";
    } else {
        e.state = TrackingState::Ok;
    }
}

}  // namespace mirage::tracking
