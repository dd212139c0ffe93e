#include "core/math/LevenbergMarquardt.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <opencv2/core.hpp>

#include "core/Error.h"

namespace mirage::lm {
namespace {

// Damping of a parameter with no curvature (J^T J_jj = 0) is not zero, so the damped system stays
// positive definite.
constexpr double kDampingFloor = 1e-12;
constexpr double kLambdaMin = 1e-9;
constexpr double kLambdaUp = 10.0;
// Accepted steps relax the damping more slowly than rejected ones raise it, so a solver that has
// just had to damp does not jump straight back to the step that failed.
constexpr double kLambdaDown = 0.2;

double sumOfSquares(const std::vector<double>& r) {
    double s = 0;
    for (double v : r) s += v * v;
    return s;
}

// Accumulates J^T J and J^T r from the blocks, given the residuals r at the same x.
class NormalSink final : public JacobianSink {
public:
    NormalSink(NormalEquations& ne, const std::vector<double>& r) : ne_(ne), r_(r) {}
    void add(size_t firstRow, size_t rows, const std::vector<int>& columns,
             const double* values) override {
        MR_CHECK(firstRow + rows <= r_.size(), "Jacobian block beyond the residuals");
        const size_t k = columns.size();
        const size_t P = size_t(ne_.parameters);
        bool dense = k == P;
        for (size_t a = 0; a < k && dense; ++a) dense = size_t(columns[a]) == a;
        if (dense) {
            // All parameters in their order (a small problem such as a pose): the same sums
            // without the column look-ups.
            for (size_t i = 0; i < rows; ++i) {
                const double* Ji = values + i * P;
                const double ri = r_[firstRow + i];
                for (size_t a = 0; a < P; ++a) {
                    if (!std::isfinite(Ji[a])) ne_.finite = false;
                    ne_.Jtr[a] += Ji[a] * ri;
                    double* row = &ne_.JtJ[a * P];
                    for (size_t b = a; b < P; ++b) row[b] += Ji[a] * Ji[b];
                }
            }
            return;
        }
        for (size_t i = 0; i < rows; ++i) {
            const double* Ji = values + i * k;
            const double ri = r_[firstRow + i];
            for (size_t a = 0; a < k; ++a) {
                if (!std::isfinite(Ji[a])) ne_.finite = false;
                const size_t ca = size_t(columns[a]);
                ne_.Jtr[ca] += Ji[a] * ri;
                // Upper triangle only (completeSymmetric() mirrors it): half the products.
                double* row = &ne_.JtJ[ca * P];
                for (size_t b = 0; b < k; ++b)
                    if (size_t(columns[b]) >= ca) row[size_t(columns[b])] += Ji[a] * Ji[b];
            }
        }
    }

    // Copies the upper triangle of J^T J into the lower one.
    void completeSymmetric() {
        const size_t P = size_t(ne_.parameters);
        for (size_t a = 0; a < P; ++a)
            for (size_t b = 0; b < a; ++b) ne_.JtJ[a * P + b] = ne_.JtJ[b * P + a];
    }

private:
    NormalEquations& ne_;
    const std::vector<double>& r_;
};

class DenseSink final : public JacobianSink {
public:
    DenseSink(std::vector<double>& J, size_t rows, int parameters)
        : J_(J), rows_(rows), P_(size_t(parameters)) {
        J_.assign(rows_ * P_, 0.0);
    }
    void add(size_t firstRow, size_t rows, const std::vector<int>& columns,
             const double* values) override {
        MR_CHECK(firstRow + rows <= rows_, "Jacobian block beyond the residuals");
        for (size_t i = 0; i < rows; ++i)
            for (size_t a = 0; a < columns.size(); ++a)
                J_[(firstRow + i) * P_ + size_t(columns[a])] += values[i * columns.size() + a];
    }

private:
    std::vector<double>& J_;
    size_t rows_, P_;
};

// Solves A x = b for symmetric positive definite A (n x n, row-major) by Cholesky, overwriting
// A with its factor. False if A is not positive definite (to working precision).
bool solveCholesky(std::vector<double>& A, int n, const std::vector<double>& b,
                   std::vector<double>& x) {
    const size_t N = size_t(n);
    for (size_t j = 0; j < N; ++j) {
        double d = A[j * N + j];
        for (size_t k = 0; k < j; ++k) d -= A[j * N + k] * A[j * N + k];
        if (!(d > 0) || !std::isfinite(d)) return false;
        const double l = std::sqrt(d);
        A[j * N + j] = l;
        for (size_t i = j + 1; i < N; ++i) {
            double s = A[i * N + j];
            for (size_t k = 0; k < j; ++k) s -= A[i * N + k] * A[j * N + k];
            A[i * N + j] = s / l;
        }
    }
    x = b;
    for (size_t i = 0; i < N; ++i) {  // L y = b
        double s = x[i];
        for (size_t k = 0; k < i; ++k) s -= A[i * N + k] * x[k];
        x[i] = s / A[i * N + i];
    }
    for (size_t i = N; i-- > 0;) {  // L^T x = y
        double s = x[i];
        for (size_t k = i + 1; k < N; ++k) s -= A[k * N + i] * x[k];
        x[i] = s / A[i * N + i];
    }
    for (double v : x)
        if (!std::isfinite(v)) return false;
    return true;
}

void applyStep(const Problem& p, std::vector<double>& x, const std::vector<double>& dx) {
    if (p.retract) {
        p.retract(x, dx);
        return;
    }
    MR_CHECK(x.size() == dx.size(), "additive step needs x and dx of the same length");
    for (size_t i = 0; i < x.size(); ++i) x[i] += dx[i];
}

// Cost at x, +inf if the residuals are not admissible or not finite.
double costAt(const Problem& p, const std::vector<double>& x, std::vector<double>& r) {
    if (!p.residuals(x, r)) return std::numeric_limits<double>::infinity();
    const double c = sumOfSquares(r);
    return std::isfinite(c) ? c : std::numeric_limits<double>::infinity();
}

}  // namespace

const char* stopName(Stop s) {
    switch (s) {
        case Stop::Converged:
            return "converged";
        case Stop::NoDecrease:
            return "no decrease";
        case Stop::MaxIterations:
            return "iteration limit";
        case Stop::NotFinite:
            return "not finite";
        case Stop::NoResiduals:
            return "no residuals";
    }
    return "?";
}

bool Report::converged() const {
    return (stop == Stop::Converged || stop == Stop::NoDecrease) && std::isfinite(finalCost);
}

std::string Report::summary() const {
    return fmt::format(
        "{} after {} steps ({} evaluations): cost {:.6g} -> {:.6g} over {} residuals",
        stopName(stop), iterations, evaluations, initialCost, finalCost, residualCount);
}

NormalEquations normalEquations(const Problem& p, const std::vector<double>& x) {
    NormalEquations ne;
    ne.parameters = p.parameters;
    ne.JtJ.assign(size_t(p.parameters) * size_t(p.parameters), 0.0);
    ne.Jtr.assign(size_t(p.parameters), 0.0);
    std::vector<double> r;
    ne.cost = costAt(p, x, r);
    ne.residualCount = r.size();
    ne.finite = std::isfinite(ne.cost);
    if (!ne.finite) return ne;
    NormalSink sink(ne, r);
    p.jacobian(x, sink);
    sink.completeSymmetric();
    return ne;
}

Report solve(const Problem& p, std::vector<double>& x, const Options& o) {
    MR_CHECK(p.parameters > 0 && p.residuals && p.jacobian, "incomplete least-squares problem");
    Report rep;
    std::vector<double> r;
    double cost = costAt(p, x, r);
    rep.evaluations = 1;
    rep.initialCost = rep.finalCost = cost;
    rep.residualCount = r.size();
    if (r.empty()) {
        rep.stop = Stop::NoResiduals;
        return rep;
    }
    if (!std::isfinite(cost)) {
        rep.stop = Stop::NotFinite;
        return rep;
    }
    const size_t P = size_t(p.parameters);
    double lambda = o.initialLambda;
    // Buffers reused across iterations (the tracker runs several small solves per frame).
    std::vector<double> dx, minusG(P), trial, r2, A;
    NormalEquations ne;
    ne.parameters = p.parameters;
    rep.stop = Stop::MaxIterations;
    for (int it = 0; it < o.maxIterations; ++it) {
        ne.JtJ.assign(P * P, 0.0);
        ne.Jtr.assign(P, 0.0);
        ne.finite = true;
        NormalSink sink(ne, r);
        p.jacobian(x, sink);
        sink.completeSymmetric();
        if (!ne.finite) {
            rep.stop = Stop::NoDecrease;
            break;
        }
        for (size_t a = 0; a < P; ++a) minusG[a] = -ne.Jtr[a];
        bool accepted = false, converged = false;
        while (lambda <= o.maxLambda) {
            A = ne.JtJ;
            for (size_t a = 0; a < P; ++a)
                A[a * P + a] += lambda * std::max(ne.JtJ[a * P + a], kDampingFloor);
            if (!solveCholesky(A, p.parameters, minusG, dx)) {
                lambda *= kLambdaUp;
                continue;
            }
            // Decrease predicted by the undamped Gauss-Newton model: -(2 g.dx + dx.A.dx).
            double gdx = 0, dAd = 0;
            for (size_t a = 0; a < P; ++a) {
                gdx += ne.Jtr[a] * dx[a];
                double Ad = 0;
                for (size_t b = 0; b < P; ++b) Ad += ne.JtJ[a * P + b] * dx[b];
                dAd += dx[a] * Ad;
            }
            const double predicted = -(2 * gdx + dAd);
            if (predicted < o.relativeTolerance * cost + 1e-300) {
                converged = true;
                break;
            }
            trial = x;
            applyStep(p, trial, dx);
            const double c2 = costAt(p, trial, r2);
            ++rep.evaluations;
            if (c2 < cost) {
                const double achieved = cost - c2;
                x.swap(trial);
                r.swap(r2);
                cost = c2;
                lambda = std::max(lambda * kLambdaDown, kLambdaMin);
                accepted = true;
                ++rep.iterations;
                if (achieved < o.achievedTolerance * (cost + achieved)) converged = true;
                break;
            }
            lambda *= kLambdaUp;
        }
        if (converged) {
            rep.stop = Stop::Converged;
            break;
        }
        if (!accepted) {
            rep.stop = Stop::NoDecrease;
            break;
        }
    }
    rep.finalCost = cost;
    rep.lambda = lambda;
    return rep;
}

Covariance covariance(const Problem& p, const std::vector<double>& x) {
    Covariance cov;
    cov.parameters = p.parameters;
    const NormalEquations ne = normalEquations(p, x);
    const int P = p.parameters;
    if (!ne.finite || ne.residualCount <= size_t(P)) return cov;
    cov.sigma2 = ne.cost / double(ne.residualCount - size_t(P));
    if (!std::isfinite(cov.sigma2)) return cov;
    // Jacobi scaling: A' = S A S with S = diag(1/sqrt(A_jj)); A^-1 = S A'^-1 S.
    std::vector<double> s(static_cast<size_t>(P), 0.0);
    for (int i = 0; i < P; ++i) {
        const double d = ne.JtJ[size_t(i * P + i)];
        if (!(d > 0) || !std::isfinite(d)) return cov;
        s[size_t(i)] = 1.0 / std::sqrt(d);
    }
    cv::Mat A(P, P, CV_64F);
    for (int i = 0; i < P; ++i)
        for (int j = 0; j < P; ++j)
            A.at<double>(i, j) = ne.JtJ[size_t(i * P + j)] * s[size_t(i)] * s[size_t(j)];
    cv::Mat w, u, vt;
    cv::SVD::compute(A, w, u, vt, cv::SVD::FULL_UV);
    if (!(w.at<double>(P - 1) > 1e-12 * w.at<double>(0))) return cov;  // singular
    // For the symmetric A' = V diag(w) V^T: (A'^-1)_ij = sum_k V_ik V_jk / w_k.
    cov.matrix.assign(size_t(P) * size_t(P), 0.0);
    for (int i = 0; i < P; ++i)
        for (int j = i; j < P; ++j) {
            double v = 0;
            for (int k = 0; k < P; ++k)
                v += vt.at<double>(k, i) * vt.at<double>(k, j) / w.at<double>(k);
            v *= s[size_t(i)] * s[size_t(j)] * cov.sigma2;
            cov.matrix[size_t(i * P + j)] = cov.matrix[size_t(j * P + i)] = v;
        }
    cov.ok = true;
    return cov;
}

std::vector<double> denseJacobian(const Problem& p, const std::vector<double>& x) {
    std::vector<double> r, J;
    p.residuals(x, r);
    DenseSink sink(J, r.size(), p.parameters);
    p.jacobian(x, sink);
    return J;
}

std::vector<double> finiteDifferenceJacobian(const Problem& p, const std::vector<double>& x,
                                             double h) {
    std::vector<double> r0;
    p.residuals(x, r0);
    const size_t m = r0.size(), P = size_t(p.parameters);
    std::vector<double> J(m * P, 0.0), rp, rm;
    for (size_t j = 0; j < P; ++j) {
        std::vector<double> dx(P, 0.0);
        auto xp = x, xm = x;
        dx[j] = h;
        applyStep(p, xp, dx);
        dx[j] = -h;
        applyStep(p, xm, dx);
        p.residuals(xp, rp);
        p.residuals(xm, rm);
        MR_CHECK(rp.size() == m && rm.size() == m, "residual count changes with the parameters");
        for (size_t i = 0; i < m; ++i) J[i * P + j] = (rp[i] - rm[i]) / (2 * h);
    }
    return J;
}

}  // namespace mirage::lm
