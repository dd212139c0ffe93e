#include "calibration/JointRefinement.h"

#include <cmath>
#include <limits>

#include <opencv2/calib3d.hpp>

namespace mirage::calib {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Intrinsic parameter i (fx fy cx cy distortion...) of a mutable or const CameraIntrinsics.
template <class Intrinsics>
auto& intrinsicRef(Intrinsics& in, int i) {
    switch (i) {
        case 0:
            return in.fx;
        case 1:
            return in.fy;
        case 2:
            return in.cx;
        case 3:
            return in.cy;
        default:
            return in.distortion[size_t(i - 4)];
    }
}

std::vector<int> freeIntrinsics(const JointProblem& p) {
    std::vector<int> free;
    for (int i = 0; i < p.intrinsicCount(); ++i)
        if (p.fixedIntrinsics.empty() || !p.fixedIntrinsics[size_t(i)]) free.push_back(i);
    return free;
}

// The intrinsics of state x (the fixed ones from the problem).
CameraIntrinsics intrinsicsOf(const JointProblem& p, const std::vector<int>& free,
                              const std::vector<double>& x) {
    CameraIntrinsics in = p.intrinsics;
    in.distortion.resize(p.intrinsics.model == DistortionModel::KannalaBrandt ? 4 : 5, 0.0);
    for (size_t k = 0; k < free.size(); ++k) intrinsicRef(in, free[k]) = x[k];
    return in;
}

cv::Vec3d vec3At(const std::vector<double>& x, size_t o) {
    return {x[o], x[o + 1], x[o + 2]};
}

double viewScale(const JointProblem& p, size_t v) {
    return p.viewScales.empty() ? 1.0 : p.viewScales[v];
}

}  // namespace

void boardResiduals(const CalibrationView& view, const CameraIntrinsics& in, const cv::Vec3d& rvec,
                    const cv::Vec3d& tvec, std::vector<double>& residuals,
                    cv::Mat* intrinsicsJacobian, cv::Mat* poseJacobian) {
    const std::vector<cv::Point3d> obj(view.boardPoints.begin(), view.boardPoints.end());
    std::vector<cv::Point2d> px;
    const bool withJacobian = intrinsicsJacobian || poseJacobian;
    cv::Mat J;
    if (in.model == DistortionModel::KannalaBrandt) {
        // Columns: fx fy cx cy k1..k4 om(3) T(3) alpha.
        if (withJacobian)
            cv::fisheye::projectPoints(obj, px, rvec, tvec, cameraMatrix(in), distortionVector(in),
                                       0.0, J);
        else
            cv::fisheye::projectPoints(obj, px, rvec, tvec, cameraMatrix(in), distortionVector(in));
        if (intrinsicsJacobian) *intrinsicsJacobian = J.colRange(0, 8);
        if (poseJacobian) *poseJacobian = J.colRange(8, 14);
    } else {
        // Columns: rvec(3) tvec(3) fx fy cx cy k1 k2 p1 p2 k3.
        if (withJacobian)
            cv::projectPoints(obj, rvec, tvec, cameraMatrix(in), distortionVector(in), px, J);
        else
            cv::projectPoints(obj, rvec, tvec, cameraMatrix(in), distortionVector(in), px);
        if (intrinsicsJacobian) *intrinsicsJacobian = J.colRange(6, 15);
        if (poseJacobian) *poseJacobian = J.colRange(0, 6);
    }
    residuals.resize(2 * px.size());
    for (size_t i = 0; i < px.size(); ++i) {
        residuals[2 * i] = px[i].x - double(view.imagePoints[i].x);
        residuals[2 * i + 1] = px[i].y - double(view.imagePoints[i].y);
    }
}

double intrinsicParameter(const CameraIntrinsics& in, int i) {
    return i < 4 ? intrinsicRef(in, i) : in.coeff(size_t(i - 4));
}

int JointProblem::intrinsicCount() const {
    return intrinsics.model == DistortionModel::KannalaBrandt ? 8 : 9;
}

double JointProblem::cost() const {
    std::vector<double> r;
    if (!leastSquares(*this).residuals(stateOf(*this), r)) return kInf;
    double sum = 0;
    for (double v : r) sum += v * v;
    return std::isfinite(sum) ? sum : kInf;
}

std::vector<double> stateOf(const JointProblem& p) {
    const std::vector<int> free = freeIntrinsics(p);
    CameraIntrinsics in = p.intrinsics;
    in.distortion.resize(p.intrinsics.model == DistortionModel::KannalaBrandt ? 4 : 5, 0.0);
    std::vector<double> x;
    for (int i : free) x.push_back(intrinsicRef(in, i));
    for (size_t v = 0; v < p.views.size(); ++v)
        for (const cv::Vec3d& w : {p.rvecs[v], p.tvecs[v]}) x.insert(x.end(), {w[0], w[1], w[2]});
    return x;
}

void setState(JointProblem& p, const std::vector<double>& x) {
    const std::vector<int> free = freeIntrinsics(p);
    p.intrinsics = intrinsicsOf(p, free, x);
    for (size_t v = 0; v < p.views.size(); ++v) {
        p.rvecs[v] = vec3At(x, free.size() + 6 * v);
        p.tvecs[v] = vec3At(x, free.size() + 6 * v + 3);
    }
}

lm::Problem leastSquares(const JointProblem& p) {
    const std::vector<int> free = freeIntrinsics(p);
    const size_t nF = free.size();
    lm::Problem ls;
    ls.parameters = int(nF + 6 * p.views.size());
    ls.residuals = [&p, free, nF](const std::vector<double>& x, std::vector<double>& r) {
        const CameraIntrinsics in = intrinsicsOf(p, free, x);
        r.clear();
        if (!in.isValid()) return false;
        std::vector<double> rv;
        for (size_t v = 0; v < p.views.size(); ++v) {
            boardResiduals(*p.views[v], in, vec3At(x, nF + 6 * v), vec3At(x, nF + 6 * v + 3), rv);
            const double scale = viewScale(p, v);
            for (double e : rv) r.push_back(scale * e);
        }
        return true;
    };
    ls.jacobian = [&p, free, nF](const std::vector<double>& x, lm::JacobianSink& sink) {
        const CameraIntrinsics in = intrinsicsOf(p, free, x);
        std::vector<double> rv;
        std::vector<int> columns(free.size() + 6);
        for (size_t k = 0; k < nF; ++k) columns[k] = int(k);
        size_t row = 0;
        for (size_t v = 0; v < p.views.size(); ++v) {
            cv::Mat Ji, Je;
            boardResiduals(*p.views[v], in, vec3At(x, nF + 6 * v), vec3At(x, nF + 6 * v + 3), rv,
                           &Ji, &Je);
            const int n = int(rv.size());
            cv::Mat block(n, int(nF) + 6, CV_64F);
            for (size_t k = 0; k < nF; ++k) Ji.col(free[k]).copyTo(block.col(int(k)));
            Je.copyTo(block.colRange(int(nF), int(nF) + 6));
            block *= viewScale(p, v);
            for (size_t c = 0; c < 6; ++c) columns[nF + c] = int(nF + 6 * v + c);
            sink.add(row, size_t(n), columns, block.ptr<double>());
            row += size_t(n);
        }
    };
    return ls;
}

double refineJointly(JointProblem& p, int maxIterations) {
    size_t pointCount = 0;
    for (const auto* v : p.views) pointCount += v->imagePoints.size();
    p.intrinsics.distortion.resize(p.intrinsics.model == DistortionModel::KannalaBrandt ? 4 : 5,
                                   0.0);
    std::vector<double> x = stateOf(p);
    lm::Options o;
    o.maxIterations = maxIterations;
    const lm::Report report = lm::solve(leastSquares(p), x, o);
    setState(p, x);
    return std::sqrt(report.finalCost / double(std::max<size_t>(pointCount, 1)));
}

cv::Mat intrinsicCovariance(const JointProblem& p) {
    const std::vector<int> free = freeIntrinsics(p);
    const lm::Covariance cov = lm::covariance(leastSquares(p), stateOf(p));
    if (!cov.ok) return {};
    const int n = p.intrinsicCount();
    cv::Mat out = cv::Mat::zeros(n, n, CV_64F);
    for (size_t a = 0; a < free.size(); ++a)
        for (size_t b = 0; b < free.size(); ++b)
            out.at<double>(free[a], free[b]) = cov.at(int(a), int(b));
    return out;
}

std::vector<double> intrinsicStdDeviations(const JointProblem& p) {
    std::vector<double> sd(size_t(p.intrinsicCount()), kInf);
    const std::vector<int> free = freeIntrinsics(p);
    const lm::Covariance cov = lm::covariance(leastSquares(p), stateOf(p));
    if (!cov.ok) return sd;
    for (double& s : sd) s = 0.0;  // fixed ones stay 0
    for (size_t k = 0; k < free.size(); ++k) {
        const double var = cov.at(int(k), int(k));
        sd[size_t(free[k])] = var >= 0 ? std::sqrt(var) : kInf;
    }
    return sd;
}

}  // namespace mirage::calib
