#pragma once
// One Levenberg-Marquardt solver for the least-squares problems of mirage: the camera pose from
// tag corners (tracking/PoseEstimator.cpp), the joint calibration of intrinsics and view poses
// (calibration/JointRefinement.cpp) and the stereo extrinsics (calibration/Extrinsics.cpp).
//
// Minimises cost(x) = sum_i r_i(x)^2. Each iteration solves the damped normal equations
//   (J^T J + lambda * D) dx = -J^T r,   D = diag(max(J^T J_jj, kDampingFloor))
// (Marquardt's scaling: the damping follows each parameter's own curvature, so focal lengths in
// pixels and distortion coefficients near 0.01 are damped alike). A step is taken only if it
// lowers the cost (then lambda /= 5, down to 1e-9), else lambda *= 10 and the step is solved
// again. It stops when the decrease predicted by the Gauss-Newton model falls below
// `relativeTolerance` times the cost, or the decrease achieved below `achievedTolerance` times
// the cost, when no damping up to `maxLambda` lowers the cost, or after `maxIterations`.
//
// Parameters: x is the problem's own state (any length); a step dx has `parameters` entries and
// is applied by `retract` (default: x + dx). So a pose can be kept as translation + unit
// quaternion and stepped by a rotation vector. The Jacobian is d r / d dx at dx = 0.
//
// Covariance of the step parameters at the optimum: (J^T J)^-1 * sigma^2 with
// sigma^2 = cost / (residuals - parameters), the residual variance per coordinate.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace mirage::lm {

// Receives the Jacobian block by block: rows [firstRow, firstRow + rows) of the residual vector,
// non-zero only in `columns` (step parameter indices); `values` is rows x columns.size(),
// row-major. Blocks may share columns but not rows.
class JacobianSink {
public:
    virtual ~JacobianSink() = default;
    virtual void add(size_t firstRow, size_t rows, const std::vector<int>& columns,
                     const double* values) = 0;
};

struct Problem {
    int parameters = 0;  // length of a step dx
    // Residuals at x into r (the callee sizes r). Returns false if x is not admissible (e.g. a
    // camera model that is no longer valid): a step there is rejected.
    std::function<bool(const std::vector<double>& x, std::vector<double>& r)> residuals;
    // The Jacobian of the residuals with respect to the step at x, into the sink.
    std::function<void(const std::vector<double>& x, JacobianSink& sink)> jacobian;
    // x <- x (+) dx. Empty: x + dx (x must then have `parameters` entries).
    std::function<void(std::vector<double>& x, const std::vector<double>& dx)> retract;
};

struct Options {
    int maxIterations = 50;
    // Stop when the decrease the Gauss-Newton model predicts for the next step, or the decrease
    // the last step achieved, is below this fraction of the cost.
    double relativeTolerance = 1e-12;
    double achievedTolerance = 1e-12;
    double initialLambda = 1e-3;
    double maxLambda = 1e12;  // no step lowers the cost even this damped: stop
};

enum class Stop {
    Converged,      // the predicted or the achieved decrease fell below the tolerance
    NoDecrease,     // no damped step lowers the cost (at a minimum, or the model is poor)
    MaxIterations,  // the iteration budget ran out while the cost still fell
    NotFinite,      // the residuals at the start are not finite or not admissible
    NoResiduals,    // nothing to fit
};
const char* stopName(Stop s);

struct Report {
    Stop stop = Stop::NoResiduals;
    int iterations = 0;        // accepted steps
    int evaluations = 0;       // residual evaluations
    double initialCost = 0;    // sum of squared residuals at the start
    double finalCost = 0;      // ... at the returned x
    size_t residualCount = 0;  // number of residuals
    double lambda = 0;         // damping at the end
    // Reached a minimum of the model: Converged or NoDecrease (with a finite cost).
    bool converged() const;
    std::string summary() const;  // one line for logs and test messages
};

// Runs LM from x (updated in place).
Report solve(const Problem& problem, std::vector<double>& x, const Options& options = {});

// J^T J and J^T r at x (dense, parameters x parameters, row-major), and the cost.
struct NormalEquations {
    int parameters = 0;
    std::vector<double> JtJ, Jtr;
    double cost = 0;
    size_t residualCount = 0;
    bool finite = true;  // residuals and Jacobian finite and admissible
};
NormalEquations normalEquations(const Problem& problem, const std::vector<double>& x);

struct Covariance {
    bool ok = false;  // false: the normal equations are singular (a parameter is unobservable)
                      // or there are no more residuals than parameters
    int parameters = 0;
    std::vector<double> matrix;  // parameters x parameters, row-major
    double sigma2 = 0;           // residual variance per coordinate
    double at(int i, int j) const { return matrix[size_t(i) * size_t(parameters) + size_t(j)]; }
};
// (J^T J)^-1 sigma^2 at x. Inverted with Jacobi scaling (so parameters of very different units
// invert together) by SVD; singular when the smallest singular value is below 1e-12 of the
// largest.
Covariance covariance(const Problem& problem, const std::vector<double>& x);

// Dense Jacobian (residuals x parameters, row-major) from the problem's callback, and the same by
// central differences of the residuals through `retract` (step h per parameter): for tests of a
// problem's analytic Jacobian.
std::vector<double> denseJacobian(const Problem& problem, const std::vector<double>& x);
std::vector<double> finiteDifferenceJacobian(const Problem& problem, const std::vector<double>& x,
                                             double h);

}  // namespace mirage::lm
