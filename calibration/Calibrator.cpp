#include "calibration/Calibrator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>

#include "calibration/CoverageMap.h"
#include "calibration/JointRefinement.h"
#include "core/Error.h"

namespace mirage::calib {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kRadToDeg = 57.29577951308232;

struct Solution {
    CameraIntrinsics intrinsics;
    std::vector<cv::Vec3d> rvecs, tvecs;  // per active view
    std::vector<double> viewRms;          // per active view, pixels
    std::vector<double> stdDeviations;    // intrinsics, +inf where unobservable
    cv::Mat covariance;                   // intrinsics, empty if singular
    double rms = 0;                       // over all active points
};

// Per-view RMS and total RMS of the residuals of a solution.
void computeErrors(const std::vector<const CalibrationView*>& views, Solution& s) {
    double total = 0;
    size_t count = 0;
    s.viewRms.clear();
    for (size_t v = 0; v < views.size(); ++v) {
        const auto projected =
            projectBoardPoints(views[v]->boardPoints, s.intrinsics, s.rvecs[v], s.tvecs[v]);
        double sum = 0;
        for (size_t i = 0; i < projected.size(); ++i) {
            const cv::Point2f d = projected[i] - views[v]->imagePoints[i];
            sum += double(d.x) * d.x + double(d.y) * d.y;
        }
        s.viewRms.push_back(std::sqrt(sum / double(projected.size())));
        total += sum;
        count += projected.size();
    }
    s.rms = std::sqrt(total / double(count));
}

JointProblem problemOf(const std::vector<const CalibrationView*>& views, const Solution& s,
                       const CalibrationOptions& o) {
    JointProblem p;
    p.views = views;
    p.intrinsics = s.intrinsics;
    p.rvecs = s.rvecs;
    p.tvecs = s.tvecs;
    if (o.model == DistortionModel::BrownConrady && o.fixK3)
        p.fixedIntrinsics = {false, false, false, false, false, false, false, false, true};
    return p;
}

Solution fromProblem(const JointProblem& p, const std::vector<const CalibrationView*>& views) {
    Solution s;
    s.intrinsics = p.intrinsics;
    s.rvecs = p.rvecs;
    s.tvecs = p.tvecs;
    computeErrors(views, s);
    s.stdDeviations = intrinsicStdDeviations(p);
    s.covariance = intrinsicCovariance(p);
    return s;
}

// A fish-eye problem over `views` for images of `size`, intrinsics and poses still to be set.
JointProblem fisheyeProblem(const std::vector<const CalibrationView*>& views, cv::Size size) {
    JointProblem p;
    p.views = views;
    p.intrinsics.width = size.width;
    p.intrinsics.height = size.height;
    p.intrinsics.model = DistortionModel::KannalaBrandt;
    return p;
}

// Own initialisation of the fish-eye problem: centred principal point, no distortion, a focal
// length candidate, and each view's pose from the planar PnP on undistorted points.
JointProblem fisheyeInitialGuess(const std::vector<const CalibrationView*>& views, cv::Size size,
                                 double focal) {
    JointProblem p = fisheyeProblem(views, size);
    auto& in = p.intrinsics;
    in.fx = in.fy = focal;
    in.cx = (size.width - 1) / 2.0;
    in.cy = (size.height - 1) / 2.0;
    in.distortion = {0, 0, 0, 0};
    for (const auto* v : views) {
        cv::Vec3d r(0, 0, 0), t(0, 0, 1);
        estimateBoardPose(*v, in, r, t);
        p.rvecs.push_back(r);
        p.tvecs.push_back(t);
    }
    return p;
}

// Board and image points of every view in the point types OpenCV's calibrators take
// (cv::calibrateCamera: float; cv::fisheye::calibrate: double).
template <class P3, class P2>
void correspondences(const std::vector<const CalibrationView*>& views,
                     std::vector<std::vector<P3>>& obj, std::vector<std::vector<P2>>& img) {
    for (const auto* v : views) {
        obj.emplace_back(v->boardPoints.begin(), v->boardPoints.end());
        img.emplace_back(v->imagePoints.begin(), v->imagePoints.end());
    }
}

Solution solvePinhole(const std::vector<const CalibrationView*>& views, cv::Size size,
                      const CalibrationOptions& o) {
    std::vector<std::vector<cv::Point3f>> obj;
    std::vector<std::vector<cv::Point2f>> img;
    correspondences(views, obj, img);
    cv::Mat K, D;
    std::vector<cv::Mat> rvecs, tvecs;
    const int flags = o.fixK3 ? cv::CALIB_FIX_K3 : 0;
    cv::calibrateCamera(obj, img, size, K, D, rvecs, tvecs, flags,
                        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS,
                                         o.maxIterations, std::numeric_limits<double>::epsilon()));
    Solution s;
    auto& in = s.intrinsics;
    in.width = size.width;
    in.height = size.height;
    in.model = DistortionModel::BrownConrady;
    in.fx = K.at<double>(0, 0);
    in.fy = K.at<double>(1, 1);
    in.cx = K.at<double>(0, 2);
    in.cy = K.at<double>(1, 2);
    in.distortion.assign(5, 0.0);
    for (int i = 0; i < 5 && i < int(D.total()); ++i) in.distortion[i] = D.at<double>(i);
    for (size_t v = 0; v < views.size(); ++v) {
        s.rvecs.emplace_back(rvecs[v].at<double>(0), rvecs[v].at<double>(1),
                             rvecs[v].at<double>(2));
        s.tvecs.emplace_back(tvecs[v].at<double>(0), tvecs[v].at<double>(1),
                             tvecs[v].at<double>(2));
    }
    computeErrors(views, s);
    // The deviations come from our Jacobian (JointRefinement.h). calibrateCameraExtended's own
    // are ~1.4x (sqrt 2) too large in the Monte-Carlo test: OpenCV 4.6 divides the residual sum
    // by the number of points, not the number of residuals (2 per point), minus parameters.
    auto problem = problemOf(views, s, o);
    s.stdDeviations = intrinsicStdDeviations(problem);
    s.covariance = intrinsicCovariance(problem);
    return s;
}

Solution solveFisheye(const std::vector<const CalibrationView*>& views, cv::Size size,
                      const CalibrationOptions& o) {
    std::vector<std::vector<cv::Point3d>> obj;
    std::vector<std::vector<cv::Point2d>> img;
    correspondences(views, obj, img);
    std::vector<JointProblem> candidates;
    try {
        cv::Matx33d K;
        cv::Vec4d D;
        std::vector<cv::Vec3d> rvecs, tvecs;
        const int flags = cv::fisheye::CALIB_RECOMPUTE_EXTRINSIC | cv::fisheye::CALIB_FIX_SKEW;
        cv::fisheye::calibrate(obj, img, size, K, D, rvecs, tvecs, flags,
                               cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS,
                                                o.maxIterations, 1e-10));
        JointProblem p = fisheyeProblem(views, size);
        auto& in = p.intrinsics;
        in.fx = K(0, 0);
        in.fy = K(1, 1);
        in.cx = K(0, 2);
        in.cy = K(1, 2);
        in.distortion = {D[0], D[1], D[2], D[3]};
        p.rvecs = rvecs;
        p.tvecs = tvecs;
        if (in.isValid()) candidates.push_back(std::move(p));
    } catch (const cv::Exception&) {
        // cv::fisheye's own initialisation fails on some steep or far off-axis views
        // ("fabs(norm_u1) > 0"); the joint refinement below starts from our own guesses instead.
    }
    size_t points = 0;
    for (const auto* v : views) points += v->imagePoints.size();
    auto rmsOf = [&](const JointProblem& p) { return std::sqrt(p.cost() / double(points)); };
    // cv::fisheye can also return its initial guess unchanged (it stalls when one view's pose
    // does not converge); a residual far above detection noise means: try our own guesses too.
    for (auto& c : candidates) refineJointly(c, o.maxIterations);
    if (candidates.empty() || !(rmsOf(candidates.front()) < 2.0)) {
        // Equidistant model: r = f * theta. Focal candidates span 120..250 degree lenses.
        for (double fov : {120.0, 160.0, 200.0, 250.0}) {
            const double focal = size.width / (fov * M_PI / 180.0);
            auto p = fisheyeInitialGuess(views, size, focal);
            refineJointly(p, o.maxIterations);
            candidates.push_back(std::move(p));
        }
    }
    size_t best = 0;
    for (size_t i = 1; i < candidates.size(); ++i)
        if (candidates[i].cost() < candidates[best].cost()) best = i;
    return fromProblem(candidates[best], views);
}

bool allFinite(const Solution& s) {
    if (!s.intrinsics.isValid() || !std::isfinite(s.rms)) return false;
    for (size_t v = 0; v < s.rvecs.size(); ++v)
        for (int i = 0; i < 3; ++i)
            if (!std::isfinite(s.rvecs[v][i]) || !std::isfinite(s.tvecs[v][i])) return false;
    return true;
}

// Joint refinement from `s` (the same views with a few corners fewer, or weighted: the optimum
// is near), each view's residuals scaled by viewScales[v] (empty = 1); the standard deviations
// then come from the weighted problem. Throws mirage::Error if the result is not finite.
Solution refit(const std::vector<const CalibrationView*>& views, const Solution& s,
               const CalibrationOptions& o, const std::vector<double>& viewScales) {
    JointProblem p = problemOf(views, s, o);
    p.viewScales = viewScales;
    refineJointly(p, o.maxIterations);
    Solution out = fromProblem(p, views);
    if (!allFinite(out))
        throw Error(
            "calibration: the joint refinement after dropping outlier corners or weighting "
            "views produced no finite result");
    return out;
}

Solution solve(const std::vector<const CalibrationView*>& views, cv::Size size,
               const CalibrationOptions& o) {
    try {
        Solution s = o.model == DistortionModel::KannalaBrandt ? solveFisheye(views, size, o)
                                                               : solvePinhole(views, size, o);
        if (!allFinite(s))
            throw Error(fmt::format(
                "calibration from {} views produced no finite result (degenerate views: all "
                "fronto-parallel or too few points?); capture views with the board tilted "
                "20-45 degrees in different directions and covering the image",
                views.size()));
        return s;
    } catch (const cv::Exception& e) {
        throw Error(fmt::format(
            "calibration from {} views failed in OpenCV ({}); the views are probably degenerate "
            "(all fronto-parallel, too few, or the board too small): capture more views with "
            "the board tilted and covering the image",
            views.size(), e.err));
    }
}

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    return v[v.size() / 2];
}

// Length of each corner's reprojection error (pixels).
std::vector<double> residualLengths(const CalibrationView& v, const CameraIntrinsics& in,
                                    const cv::Vec3d& rvec, const cv::Vec3d& tvec) {
    const auto projected = projectBoardPoints(v.boardPoints, in, rvec, tvec);
    std::vector<double> r(projected.size());
    for (size_t i = 0; i < projected.size(); ++i) r[i] = cv::norm(projected[i] - v.imagePoints[i]);
    return r;
}

// Per-coordinate noise (pixels) from residual lengths: the median length of a 2D Gaussian error
// is sigma sqrt(2 ln 2) = 1.1774 sigma; the median ignores the outliers being looked for.
double noiseOf(const std::vector<double>& lengths) {
    return median(lengths) / 1.1774;
}

// Why a view cannot be used at all (empty = usable).
std::string validateView(const CalibrationView& v, cv::Size size) {
    if (v.imagePoints.size() != v.boardPoints.size())
        return fmt::format("{} image points but {} board points", v.imagePoints.size(),
                           v.boardPoints.size());
    if (v.imagePoints.size() < 4)
        return fmt::format("only {} board points (at least 4 needed)", v.imagePoints.size());
    for (size_t i = 0; i < v.imagePoints.size(); ++i) {
        const auto& p = v.imagePoints[i];
        const auto& b = v.boardPoints[i];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(b.x) ||
            !std::isfinite(b.y) || !std::isfinite(b.z))
            return "non-finite point coordinates";
        if (p.x < -0.5f || p.y < -0.5f || p.x > size.width - 0.5f || p.y > size.height - 0.5f)
            return fmt::format("point ({:.1f}, {:.1f}) lies outside the {}x{} image", p.x, p.y,
                               size.width, size.height);
        if (std::abs(b.z) > 1e-9f) return "board points are not in the board's z = 0 plane";
    }
    return {};
}

}  // namespace

std::vector<std::string> parameterNames(DistortionModel model) {
    if (model == DistortionModel::KannalaBrandt)
        return {"fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4"};
    return {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"};
}

cv::Mat cameraMatrix(const CameraIntrinsics& in) {
    return (cv::Mat_<double>(3, 3) << in.fx, 0, in.cx, 0, in.fy, in.cy, 0, 0, 1);
}

cv::Mat distortionVector(const CameraIntrinsics& in) {
    const int n = in.model == DistortionModel::KannalaBrandt ? 4 : 5;
    cv::Mat d(1, n, CV_64F);
    for (int i = 0; i < n; ++i) d.at<double>(i) = in.coeff(size_t(i));
    return d;
}

std::vector<cv::Point2f> projectBoardPoints(const std::vector<cv::Point3f>& boardPoints,
                                            const CameraIntrinsics& in, const cv::Vec3d& rvec,
                                            const cv::Vec3d& tvec) {
    std::vector<cv::Point2f> out;
    if (boardPoints.empty()) return out;
    if (in.model == DistortionModel::KannalaBrandt) {
        std::vector<cv::Point3d> obj(boardPoints.begin(), boardPoints.end());
        std::vector<cv::Point2d> px;
        cv::fisheye::projectPoints(obj, px, rvec, tvec, cameraMatrix(in), distortionVector(in));
        out.assign(px.begin(), px.end());
    } else {
        cv::projectPoints(boardPoints, rvec, tvec, cameraMatrix(in), distortionVector(in), out);
    }
    return out;
}

bool estimateBoardPose(const CalibrationView& view, const CameraIntrinsics& in, cv::Vec3d& rvec,
                       cv::Vec3d& tvec) {
    if (view.imagePoints.size() < 4 || view.imagePoints.size() != view.boardPoints.size())
        return false;
    std::vector<cv::Point2f> normalized;
    try {
        if (in.model == DistortionModel::KannalaBrandt)
            cv::fisheye::undistortPoints(view.imagePoints, normalized, cameraMatrix(in),
                                         distortionVector(in));
        else
            cv::undistortPoints(view.imagePoints, normalized, cameraMatrix(in),
                                distortionVector(in));
        // IPPE: the exact planar solution (board points at z = 0), refined on reprojection.
        if (!cv::solvePnP(view.boardPoints, normalized, cv::Mat::eye(3, 3, CV_64F), cv::Mat(), rvec,
                          tvec, false, cv::SOLVEPNP_IPPE))
            return false;
    } catch (const cv::Exception&) {
        return false;
    }
    for (int i = 0; i < 3; ++i)
        if (!std::isfinite(rvec[i]) || !std::isfinite(tvec[i])) return false;
    return true;
}

void boardTilt(const cv::Vec3d& rvec, double& tiltDeg, double& directionDeg) {
    cv::Matx33d R;
    cv::Rodrigues(rvec, R);
    // The board's +Z axis in camera coordinates; fronto-parallel means it lies along the axis.
    const cv::Vec3d n(R(0, 2), R(1, 2), R(2, 2));
    tiltDeg = std::acos(std::min(1.0, std::abs(n[2]))) * kRadToDeg;
    // Direction of the normal's sideways component, with the sign fixed so it points toward
    // the camera (n_z < 0 means the normal points at the camera already).
    const double sgn = n[2] <= 0 ? 1.0 : -1.0;
    directionDeg = std::atan2(sgn * n[1], sgn * n[0]) * kRadToDeg;
}

void boardTiltToLineOfSight(const cv::Vec3d& rvec, const cv::Vec3d& tvec,
                            const cv::Point3f& boardCentre, double& tiltDeg, double& directionDeg) {
    cv::Matx33d R;
    cv::Rodrigues(rvec, R);
    const cv::Vec3d n(R(0, 2), R(1, 2), R(2, 2));
    const cv::Vec3d c = R * cv::Vec3d(boardCentre.x, boardCentre.y, boardCentre.z) + tvec;
    const cv::Vec3d los = c / cv::norm(c);
    const double along = n.dot(los);
    tiltDeg = std::acos(std::min(1.0, std::abs(along))) * kRadToDeg;
    // The normal's component across the line of sight, pointing back toward the camera.
    const double sgn = along <= 0 ? 1.0 : -1.0;
    const cv::Vec3d across = sgn * (n - along * los);
    directionDeg = std::atan2(across[1], across[0]) * kRadToDeg;
}

double projectionStdPx(const CameraIntrinsics& in, const cv::Mat& covariance,
                       const cv::Vec3d& direction) {
    if (covariance.empty()) return kInf;
    const int n = covariance.rows;
    const glm::dvec3 d(direction[0], direction[1], direction[2]);
    const auto base = in.project(d);
    if (!base) return kInf;
    // d(pixel)/d(parameter) by central differences (steps relative to each parameter's scale).
    cv::Mat G(2, n, CV_64F);
    for (int i = 0; i < n; ++i) {
        CameraIntrinsics a = in, b = in;
        a.distortion.resize(n - 4, 0.0);
        b.distortion.resize(n - 4, 0.0);
        auto ref = [](CameraIntrinsics& c, int k) -> double& {
            return k == 0   ? c.fx
                   : k == 1 ? c.fy
                   : k == 2 ? c.cx
                   : k == 3 ? c.cy
                            : c.distortion[size_t(k - 4)];
        };
        const double h = i < 4 ? 1e-3 : 1e-6;
        ref(a, i) += h;
        ref(b, i) -= h;
        const auto pa = a.project(d), pb = b.project(d);
        if (!pa || !pb) return kInf;
        G.at<double>(0, i) = (pa->x - pb->x) / (2 * h);
        G.at<double>(1, i) = (pa->y - pb->y) / (2 * h);
    }
    const cv::Mat S = G * covariance * G.t();
    return std::sqrt(std::max(0.0, S.at<double>(0, 0) + S.at<double>(1, 1)));
}

CameraCalibration calibrationForFile(const CalibrationResult& result) {
    CameraCalibration c = result.calibration;
    const bool allFiniteStd = std::all_of(c.stdDeviations.begin(), c.stdDeviations.end(),
                                          [](double v) { return std::isfinite(v); });
    if (!allFiniteStd) {
        c.stdDeviations.clear();
        c.reliable = false;
        c.unreliableReason += std::string(c.unreliableReason.empty() ? "" : "; ") +
                              "standard deviations omitted: some parameters are unobservable";
    }
    return c;
}

int CalibrationResult::usedViewCount() const {
    return int(
        std::count_if(views.begin(), views.end(), [](const auto& v) { return !v.rejected; }));
}

double CalibrationResult::relativeFocalStd() const {
    const auto& c = calibration;
    if (c.stdDeviations.size() < 2 || !(c.intrinsics.fx > 0) || !(c.intrinsics.fy > 0)) return kInf;
    const double r =
        std::max(c.stdDeviations[0] / c.intrinsics.fx, c.stdDeviations[1] / c.intrinsics.fy);
    return std::isfinite(r) ? r : kInf;
}

namespace {

// Screens every view (enough points inside the image): the usable ones' indices; the others
// are marked rejected with the reason in `result`.
std::vector<size_t> usableViews(const std::vector<CalibrationView>& views, cv::Size imageSize,
                                CalibrationResult& result) {
    std::vector<size_t> active;
    for (size_t i = 0; i < views.size(); ++i) {
        ViewResult vr;
        vr.name = views[i].name;
        vr.pointCount = int(views[i].imagePoints.size());
        const std::string problem = validateView(views[i], imageSize);
        if (!problem.empty()) {
            vr.rejected = true;
            vr.rejectReason = problem;
        } else {
            active.push_back(i);
        }
        vr.detector = views[i].detector;
        vr.unrefinedCorners = views[i].unrefinedCorners;
        result.views.push_back(vr);
    }
    if (active.empty())
        throw Error(fmt::format(
            "calibration: none of the {} views is usable (each needs at least 4 board points "
            "inside the image); check that the board was detected",
            views.size()));
    return active;
}

// The views in use, as the solver takes them.
std::vector<const CalibrationView*> inUse(const std::vector<CalibrationView>& work,
                                          const std::vector<size_t>& active) {
    std::vector<const CalibrationView*> c;
    for (size_t i : active) c.push_back(&work[i]);
    return c;
}

// Solves, then drops the worst view while it is an outlier (its RMS above outlierFactor x the
// median and outlierMinErrorPx), within the rejection budget; re-solved after each drop.
Solution solveRejectingOutlierViews(const std::vector<CalibrationView>& work,
                                    std::vector<size_t>& active, cv::Size imageSize,
                                    const CalibrationOptions& o, CalibrationResult& result) {
    const size_t usable = active.size();
    const size_t maxRejected = size_t(std::floor(o.maxRejectedFraction * double(usable)));
    while (true) {
        Solution s = solve(inUse(work, active), imageSize, o);
        const double med = median(s.viewRms);
        const auto worst =
            size_t(std::max_element(s.viewRms.begin(), s.viewRms.end()) - s.viewRms.begin());
        const double worstRms = s.viewRms[worst];
        const bool outlier = worstRms > o.outlierFactor * med && worstRms > o.outlierMinErrorPx;
        if (!outlier || usable - active.size() >= maxRejected ||
            int(active.size()) - 1 < std::max(o.minViews, 2))
            return s;
        auto& vr = result.views[active[worst]];
        vr.rejected = true;
        vr.rmsPx = worstRms;
        vr.rejectReason = fmt::format("outlier: RMS {:.3f} px > {:.1f} x median {:.3f} px",
                                      worstRms, o.outlierFactor, med);
        active.erase(active.begin() + long(worst));
    }
}

// Outlier corners, worst first in each view per round (a gross error inflates its neighbours'
// residuals through the fit), re-solved after each round. Dropped corners leave `work` and are
// listed in `dropped`.
Solution dropOutlierCorners(Solution s, const std::vector<CalibrationView>& views,
                            std::vector<CalibrationView>& work, const std::vector<size_t>& active,
                            std::vector<std::vector<DroppedCorner>>& dropped,
                            const CalibrationOptions& o) {
    for (int round = 0; round < 10; ++round) {
        bool any = false;
        for (size_t k = 0; k < active.size(); ++k) {
            CalibrationView& v = work[active[k]];
            const std::vector<double> r = residualLengths(v, s.intrinsics, s.rvecs[k], s.tvecs[k]);
            const double noise = noiseOf(r);
            const double limit = std::max(o.cornerOutlierSigmas * noise, o.cornerOutlierMinPx);
            const size_t worst = size_t(std::max_element(r.begin(), r.end()) - r.begin());
            const size_t original = views[active[k]].imagePoints.size();
            const size_t mayDrop =
                size_t(std::floor(o.maxRejectedCornerFraction * double(original)));
            if (!(r[worst] > limit) || dropped[active[k]].size() >= mayDrop ||
                v.imagePoints.size() <= 6)
                continue;
            dropped[active[k]].push_back({v.boardPoints[worst], v.imagePoints[worst], r[worst]});
            v.boardPoints.erase(v.boardPoints.begin() + long(worst));
            v.imagePoints.erase(v.imagePoints.begin() + long(worst));
            any = true;
        }
        if (!any) break;
        s = refit(inUse(work, active), s, o, {});
    }
    return s;
}

// Views weighted by their measured noise: one noisier than 1.5x the median view counts
// (median / noise)^2 as much per corner. Returns the per-view residual scales (1: unweighted).
std::vector<double> weightByNoise(Solution& s, const std::vector<CalibrationView>& work,
                                  const std::vector<size_t>& active, const CalibrationOptions& o) {
    std::vector<double> noise(active.size()), scales(active.size(), 1.0);
    for (size_t k = 0; k < active.size(); ++k)
        noise[k] = noiseOf(residualLengths(work[active[k]], s.intrinsics, s.rvecs[k], s.tvecs[k]));
    const double medianNoise = median(noise);
    bool weighted = false;
    if (o.weightViewsByNoise && medianNoise > 0)
        for (size_t k = 0; k < active.size(); ++k)
            if (noise[k] > 1.5 * medianNoise) {
                scales[k] = medianNoise / noise[k];
                weighted = true;
            }
    if (weighted) s = refit(inUse(work, active), s, o, scales);
    return scales;
}

// The solution into the result: intrinsics, and per used view its fit, tilt and reach (the
// corners' angles off the axis, from the fitted pose: exact, no inversion of the lens
// polynomial, and their distance from the principal point).
void describeViews(const Solution& s, const std::vector<CalibrationView>& work,
                   const std::vector<size_t>& active,
                   const std::vector<std::vector<DroppedCorner>>& dropped,
                   const std::vector<double>& scales, const CalibrationOptions& o,
                   CalibrationResult& result) {
    auto& c = result.calibration;
    c.intrinsics = s.intrinsics;
    c.avgReprojectionError = s.rms;
    c.stdDeviations = s.stdDeviations;
    c.viewCount = int(active.size());
    result.intrinsicCovariance = s.covariance;
    double reachDeg = 0, reachRadius = 0;
    for (size_t k = 0; k < active.size(); ++k) {
        const CalibrationView& v = work[active[k]];
        auto& vr = result.views[active[k]];
        vr.rmsPx = s.viewRms[k];
        vr.rvec = s.rvecs[k];
        vr.tvec = s.tvecs[k];
        vr.pointCount = int(v.imagePoints.size());
        vr.droppedCorners = dropped[active[k]];
        vr.noisePx = noiseOf(residualLengths(v, s.intrinsics, s.rvecs[k], s.tvecs[k]));
        vr.weight = scales[k] * scales[k];
        result.droppedCornerCount += int(vr.droppedCorners.size());
        if (o.model == DistortionModel::KannalaBrandt) {
            cv::Point3f centre(0, 0, 0);
            for (const auto& b : v.boardPoints) centre += b;
            centre *= 1.0f / float(v.boardPoints.size());
            boardTiltToLineOfSight(vr.rvec, vr.tvec, centre, vr.tiltDeg, vr.tiltDirectionDeg);
        } else {
            boardTilt(vr.rvec, vr.tiltDeg, vr.tiltDirectionDeg);
        }
        cv::Matx33d R;
        cv::Rodrigues(vr.rvec, R);
        for (size_t i = 0; i < v.boardPoints.size(); ++i) {
            const auto& b = v.boardPoints[i];
            const cv::Vec3d p = R * cv::Vec3d(b.x, b.y, b.z) + vr.tvec;
            const double angle = std::atan2(std::hypot(p[0], p[1]), p[2]) * kRadToDeg;
            vr.maxOffAxisDeg = std::max(vr.maxOffAxisDeg, angle);
            reachRadius = std::max(reachRadius, std::hypot(v.imagePoints[i].x - c.intrinsics.cx,
                                                           v.imagePoints[i].y - c.intrinsics.cy));
        }
        reachDeg = std::max(reachDeg, vr.maxOffAxisDeg);
        result.maxTiltDeg = std::max(result.maxTiltDeg, vr.tiltDeg);
        c.perViewErrors.push_back(s.viewRms[k]);
    }
    c.reachDeg = reachDeg;
    c.reachRadiusPx = reachRadius;
}

// Reliability: every reason is collected, so the user sees all that is wrong at once.
void judgeReliability(size_t usedViews, cv::Size imageSize, const CalibrationOptions& o,
                      CalibrationResult& result) {
    auto& c = result.calibration;
    std::vector<std::string> reasons;
    if (int(usedViews) < o.minViews)
        reasons.push_back(
            fmt::format("only {} usable views (at least {} needed)", usedViews, o.minViews));
    if (result.maxTiltDeg < o.minMaxTiltDeg)
        reasons.push_back(fmt::format(
            "all views are nearly fronto-parallel (largest tilt {:.1f} deg < {:.0f} deg): the "
            "focal length is unobservable; tilt the board 20-45 degrees in several directions",
            result.maxTiltDeg, o.minMaxTiltDeg));
    const double relF = result.relativeFocalStd();
    if (!(relF <= o.maxRelativeFocalStd))
        reasons.push_back(
            std::isfinite(relF)
                ? fmt::format("focal length standard deviation is {:.2f}% of its value (limit "
                              "{:.2f}%)",
                              100 * relF, 100 * o.maxRelativeFocalStd)
                : std::string("focal length is unobservable from these views (singular "
                              "normal equations)"));
    const double ppLimit = o.maxPrincipalPointStd * imageSize.width;
    if (c.stdDeviations.size() >= 4 &&
        !(c.stdDeviations[2] <= ppLimit && c.stdDeviations[3] <= ppLimit))
        reasons.push_back(
            fmt::format("principal point standard deviation ({:.2f}, {:.2f}) px exceeds {:.1f} px",
                        c.stdDeviations[2], c.stdDeviations[3], ppLimit));
    c.reliable = reasons.empty();
    for (size_t i = 0; i < reasons.size(); ++i) c.unreliableReason += (i ? "; " : "") + reasons[i];
}

// Coverage warnings: distortion far from every corner is extrapolated; for a fish-eye, whose
// distortion is decided toward the rim, the rings off-axis (through the fitted lens) that the
// image can hold but no used corner reached.
void warnAboutCoverage(const std::vector<CalibrationView>& views, const std::vector<size_t>& active,
                       cv::Size imageSize, CalibrationResult& result) {
    float minX = 1e9f, minY = 1e9f, maxX = -1e9f, maxY = -1e9f;
    for (size_t i : active)
        for (const auto& p : views[i].imagePoints) {
            minX = std::min(minX, p.x);
            minY = std::min(minY, p.y);
            maxX = std::max(maxX, p.x);
            maxY = std::max(maxY, p.y);
        }
    const double covered =
        double(maxX - minX) * double(maxY - minY) / (double(imageSize.width) * imageSize.height);
    if (covered < 0.5)
        result.warnings.push_back(
            fmt::format("the corners span only {:.0f}% of the image: distortion near the edges is "
                        "extrapolated; move the board into the corners",
                        100 * covered));
    const CameraIntrinsics& lens = result.calibration.intrinsics;
    if (lens.model == DistortionModel::KannalaBrandt) {
        CoverageMap rings(imageSize);
        rings.setAngularLens(lens);
        for (size_t i : active) rings.add(views[i].imagePoints);
        for (const auto& missing : rings.missingRings())
            result.warnings.push_back(
                missing + ": the model is extrapolated there; add views toward the rim");
    }
}

}  // namespace

CalibrationResult calibrate(const std::vector<CalibrationView>& views, cv::Size imageSize,
                            const CalibrationOptions& o) {
    if (imageSize.width <= 0 || imageSize.height <= 0)
        throw Error(fmt::format("calibration: invalid image size {}x{}", imageSize.width,
                                imageSize.height));
    CalibrationResult result;
    result.parameterNames = parameterNames(o.model);
    std::vector<size_t> active = usableViews(views, imageSize, result);
    // Working copies: outlier corners are dropped from these.
    std::vector<CalibrationView> work(views.begin(), views.end());
    std::vector<std::vector<DroppedCorner>> dropped(views.size());
    Solution s = solveRejectingOutlierViews(work, active, imageSize, o, result);
    s = dropOutlierCorners(std::move(s), views, work, active, dropped, o);
    const std::vector<double> scales = weightByNoise(s, work, active, o);
    describeViews(s, work, active, dropped, scales, o, result);
    judgeReliability(active.size(), imageSize, o, result);
    warnAboutCoverage(views, active, imageSize, result);
    return result;
}

}  // namespace mirage::calib
