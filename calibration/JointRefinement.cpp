#include "calibration/JointRefinement.h"

#include <cmath>
#include <limits>

#include <opencv2/calib3d.hpp>

namespace mirage::calib {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Residuals (projected - observed, 2n x 1) and Jacobians w.r.t. the intrinsics (2n x nI, our
// order fx fy cx cy dist...) and the pose (2n x 6, rvec then tvec) of one view.
void viewJacobian(const CalibrationView& view, const CameraIntrinsics& in, const cv::Vec3d& rvec,
                  const cv::Vec3d& tvec, cv::Mat& residual, cv::Mat& Ji, cv::Mat& Je) {
    const std::vector<cv::Point3d> obj(view.boardPoints.begin(), view.boardPoints.end());
    std::vector<cv::Point2d> px;
    cv::Mat J;
    const int n = int(obj.size());
    if (in.model == DistortionModel::KannalaBrandt) {
        // Columns: fx fy cx cy k1..k4 om(3) T(3) alpha.
        cv::fisheye::projectPoints(obj, px, rvec, tvec, cameraMatrix(in), distortionVector(in), 0.0,
                                   J);
        Ji = J.colRange(0, 8);
        Je = J.colRange(8, 14);
    } else {
        // Columns: rvec(3) tvec(3) fx fy cx cy k1 k2 p1 p2 k3.
        cv::projectPoints(obj, rvec, tvec, cameraMatrix(in), distortionVector(in), px, J);
        Ji = J.colRange(6, 15);
        Je = J.colRange(0, 6);
    }
    residual.create(2 * n, 1, CV_64F);
    for (int i = 0; i < n; ++i) {
        residual.at<double>(2 * i) = px[size_t(i)].x - view.imagePoints[size_t(i)].x;
        residual.at<double>(2 * i + 1) = px[size_t(i)].y - view.imagePoints[size_t(i)].y;
    }
}

double& intrinsicRef(CameraIntrinsics& in, int i) {
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

struct Normal {
    cv::Mat A, g;  // J^T J and J^T r over the free parameters
    std::vector<int> freeIntrinsics;
    int residualCount = 0;
};

Normal buildNormal(const JointProblem& p) {
    Normal ne;
    const int nI = p.intrinsicCount();
    for (int i = 0; i < nI; ++i)
        if (p.fixedIntrinsics.empty() || !p.fixedIntrinsics[size_t(i)])
            ne.freeIntrinsics.push_back(i);
    const int nF = int(ne.freeIntrinsics.size()), nV = int(p.views.size());
    const int P = nF + 6 * nV;
    ne.A = cv::Mat::zeros(P, P, CV_64F);
    ne.g = cv::Mat::zeros(P, 1, CV_64F);
    for (int v = 0; v < nV; ++v) {
        cv::Mat r, Ji, Je;
        viewJacobian(*p.views[size_t(v)], p.intrinsics, p.rvecs[size_t(v)], p.tvecs[size_t(v)], r,
                     Ji, Je);
        ne.residualCount += r.rows;
        cv::Mat Jf(r.rows, nF + 6, CV_64F);
        for (int k = 0; k < nF; ++k) Ji.col(ne.freeIntrinsics[size_t(k)]).copyTo(Jf.col(k));
        Je.copyTo(Jf.colRange(nF, nF + 6));
        const cv::Mat local = Jf.t() * Jf, localG = Jf.t() * r;
        auto map = [&](int k) { return k < nF ? k : nF + 6 * v + (k - nF); };
        for (int a = 0; a < nF + 6; ++a) {
            ne.g.at<double>(map(a)) += localG.at<double>(a);
            for (int b = 0; b < nF + 6; ++b)
                ne.A.at<double>(map(a), map(b)) += local.at<double>(a, b);
        }
    }
    return ne;
}

bool plausible(const CameraIntrinsics& in) {
    return in.isValid();
}

}  // namespace

int JointProblem::intrinsicCount() const {
    return intrinsics.model == DistortionModel::KannalaBrandt ? 8 : 9;
}

double JointProblem::cost() const {
    double sum = 0;
    for (size_t v = 0; v < views.size(); ++v) {
        const auto px = projectBoardPoints(views[v]->boardPoints, intrinsics, rvecs[v], tvecs[v]);
        for (size_t i = 0; i < px.size(); ++i) {
            const double dx = double(px[i].x) - views[v]->imagePoints[i].x;
            const double dy = double(px[i].y) - views[v]->imagePoints[i].y;
            sum += dx * dx + dy * dy;
        }
    }
    return std::isfinite(sum) ? sum : kInf;
}

double refineJointly(JointProblem& p, int maxIterations) {
    size_t pointCount = 0;
    for (const auto* v : p.views) pointCount += v->imagePoints.size();
    const size_t distCount = p.intrinsics.model == DistortionModel::KannalaBrandt ? 4 : 5;
    p.intrinsics.distortion.resize(distCount, 0.0);
    double cost = p.cost();
    double lambda = 1e-3;
    for (int it = 0; it < maxIterations && std::isfinite(cost); ++it) {
        const Normal ne = buildNormal(p);
        const int P = ne.A.rows, nF = int(ne.freeIntrinsics.size());
        bool accepted = false;
        double newCost = cost;
        while (lambda < 1e12) {
            cv::Mat A = ne.A.clone();
            for (int i = 0; i < P; ++i) A.at<double>(i, i) *= 1.0 + lambda;
            cv::Mat delta;
            if (!cv::solve(A, -ne.g, delta, cv::DECOMP_CHOLESKY) &&
                !cv::solve(A, -ne.g, delta, cv::DECOMP_SVD)) {
                lambda *= 10;
                continue;
            }
            JointProblem trial = p;
            for (int k = 0; k < nF; ++k)
                intrinsicRef(trial.intrinsics, ne.freeIntrinsics[size_t(k)]) += delta.at<double>(k);
            for (size_t v = 0; v < p.views.size(); ++v)
                for (int c = 0; c < 3; ++c) {
                    trial.rvecs[v][c] += delta.at<double>(nF + 6 * int(v) + c);
                    trial.tvecs[v][c] += delta.at<double>(nF + 6 * int(v) + 3 + c);
                }
            newCost = plausible(trial.intrinsics) ? trial.cost() : kInf;
            if (newCost < cost) {
                p = std::move(trial);
                accepted = true;
                lambda = std::max(lambda / 10, 1e-9);
                break;
            }
            lambda *= 10;
        }
        if (!accepted) break;
        const double decrease = (cost - newCost) / std::max(cost, 1e-300);
        cost = newCost;
        if (decrease < 1e-12) break;
    }
    return std::sqrt(cost / double(std::max<size_t>(pointCount, 1)));
}

std::vector<double> intrinsicStdDeviations(const JointProblem& p) {
    const int nI = p.intrinsicCount();
    std::vector<double> sd(size_t(nI), kInf);
    const Normal ne = buildNormal(p);
    const int P = ne.A.rows, nF = int(ne.freeIntrinsics.size());
    const int dof = ne.residualCount - P;
    if (dof <= 0) return sd;
    const double sigma2 = p.cost() / dof;
    if (!std::isfinite(sigma2)) return sd;
    // Jacobi scaling so that focal lengths (hundreds of px) and k's (~0.01) invert together.
    cv::Mat scale(P, 1, CV_64F);
    for (int i = 0; i < P; ++i) {
        const double d = ne.A.at<double>(i, i);
        if (!(d > 0) || !std::isfinite(d)) return sd;
        scale.at<double>(i) = 1.0 / std::sqrt(d);
    }
    cv::Mat A = ne.A.clone();
    for (int i = 0; i < P; ++i)
        for (int j = 0; j < P; ++j) A.at<double>(i, j) *= scale.at<double>(i) * scale.at<double>(j);
    cv::Mat w, u, vt;
    cv::SVD::compute(A, w, u, vt, cv::SVD::FULL_UV);
    if (!(w.at<double>(P - 1) > 1e-12 * w.at<double>(0))) return sd;  // singular: unobservable
    for (int i = 0; i < nI; ++i) sd[size_t(i)] = 0.0;                 // fixed ones stay 0
    for (int k = 0; k < nF; ++k) {
        // (A^-1)_kk = sum_j V_kj^2 / w_j for the symmetric A = V diag(w) V^T.
        double var = 0;
        for (int j = 0; j < P; ++j) {
            const double vkj = vt.at<double>(j, k);
            var += vkj * vkj / w.at<double>(j);
        }
        var *= scale.at<double>(k) * scale.at<double>(k) * sigma2;
        sd[size_t(ne.freeIntrinsics[size_t(k)])] = var >= 0 ? std::sqrt(var) : kInf;
    }
    return sd;
}

}  // namespace mirage::calib
