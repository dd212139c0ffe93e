// core/math/LevenbergMarquardt.h on problems with known answers: a curve fit from far away, a
// linear fit whose covariance has a closed form, an inadmissible region the solver must not step
// into, an unobservable parameter, and a manifold state stepped through `retract`.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/math/LevenbergMarquardt.h"

namespace mirage::lm {
namespace {

// y = a * exp(b * t) sampled at t = 0..1 with small deterministic noise; parameters (a, b).
struct ExpFit {
    std::vector<double> t, y;
    ExpFit() {
        std::mt19937 rng(7);
        std::normal_distribution<double> noise(0.0, 0.01);
        for (int i = 0; i <= 20; ++i) {
            t.push_back(i / 20.0);
            y.push_back(2.0 * std::exp(-1.5 * t.back()) + noise(rng));
        }
    }
    Problem problem() const {
        Problem p;
        p.parameters = 2;
        p.residuals = [this](const std::vector<double>& x, std::vector<double>& r) {
            r.resize(t.size());
            for (size_t i = 0; i < t.size(); ++i) r[i] = x[0] * std::exp(x[1] * t[i]) - y[i];
            return true;
        };
        p.jacobian = [this](const std::vector<double>& x, JacobianSink& sink) {
            std::vector<double> J;
            for (double ti : t)
                J.insert(J.end(), {std::exp(x[1] * ti), x[0] * ti * std::exp(x[1] * ti)});
            sink.add(0, t.size(), {0, 1}, J.data());
        };
        return p;
    }
};

TEST(LevenbergMarquardt, FitsACurveFromFarAway) {
    const ExpFit fit;
    std::vector<double> x = {10.0, 3.0};  // far off: the first Gauss-Newton steps overshoot
    const Report rep = solve(fit.problem(), x);
    EXPECT_TRUE(rep.converged()) << rep.summary();
    EXPECT_EQ(rep.stop, Stop::Converged) << rep.summary();
    EXPECT_NEAR(x[0], 2.0, 0.02);
    EXPECT_NEAR(x[1], -1.5, 0.03);
    EXPECT_LT(rep.finalCost, rep.initialCost);
    EXPECT_EQ(rep.residualCount, 21u);
    // The analytic Jacobian agrees with central differences.
    const auto J = denseJacobian(fit.problem(), x);
    const auto Jfd = finiteDifferenceJacobian(fit.problem(), x, 1e-6);
    ASSERT_EQ(J.size(), Jfd.size());
    for (size_t i = 0; i < J.size(); ++i) EXPECT_NEAR(J[i], Jfd[i], 1e-6) << i;
}

// Straight line y = c0 + c1 t: LM lands on the normal-equation solution in one step and the
// covariance is (X^T X)^-1 sigma^2 with sigma^2 = RSS / (n - 2), in closed form.
TEST(LevenbergMarquardt, LinearFitAndItsCovariance) {
    const std::vector<double> t = {0, 1, 2, 3, 4, 5}, y = {1.1, 2.9, 5.2, 6.8, 9.1, 11.0};
    Problem p;
    p.parameters = 2;
    p.residuals = [&](const std::vector<double>& x, std::vector<double>& r) {
        r.resize(t.size());
        for (size_t i = 0; i < t.size(); ++i) r[i] = x[0] + x[1] * t[i] - y[i];
        return true;
    };
    p.jacobian = [&](const std::vector<double>&, JacobianSink& sink) {
        for (size_t i = 0; i < t.size(); ++i) {
            const double row[2] = {1.0, t[i]};
            sink.add(i, 1, {0, 1}, row);
        }
    };
    std::vector<double> x = {0, 0};
    const Report rep = solve(p, x);
    EXPECT_TRUE(rep.converged()) << rep.summary();
    const double n = 6, St = 15, Stt = 55, Sy = 36.1,
                 Sty = 0 * 1.1 + 2.9 + 10.4 + 20.4 + 36.4 + 55.0;
    const double det = n * Stt - St * St;
    const double c1 = (n * Sty - St * Sy) / det, c0 = (Sy - c1 * St) / n;
    EXPECT_NEAR(x[0], c0, 1e-6);
    EXPECT_NEAR(x[1], c1, 1e-6);
    double rss = 0;
    for (size_t i = 0; i < t.size(); ++i) rss += std::pow(c0 + c1 * t[i] - y[i], 2);
    const double s2 = rss / (n - 2);
    const Covariance c = covariance(p, x);
    ASSERT_TRUE(c.ok);
    EXPECT_NEAR(c.sigma2, s2, 1e-9);
    EXPECT_NEAR(c.at(0, 0), s2 * Stt / det, 1e-9);
    EXPECT_NEAR(c.at(1, 1), s2 * n / det, 1e-9);
    EXPECT_NEAR(c.at(0, 1), -s2 * St / det, 1e-9);
    EXPECT_NEAR(c.at(1, 0), c.at(0, 1), 1e-15);
}

// The residuals refuse x[0] <= 0 (like an invalid camera model): the minimum of (x - (-1))^2 lies
// there, so the solver must stop at an admissible point, never return the refused one.
TEST(LevenbergMarquardt, NeverStepsIntoAnInadmissibleRegion) {
    Problem p;
    p.parameters = 1;
    p.residuals = [](const std::vector<double>& x, std::vector<double>& r) {
        r = {x[0] + 1.0};
        return x[0] > 0;
    };
    p.jacobian = [](const std::vector<double>&, JacobianSink& sink) {
        const double one = 1.0;
        sink.add(0, 1, {0}, &one);
    };
    std::vector<double> x = {2.0};
    const Report rep = solve(p, x);
    EXPECT_GT(x[0], 0.0);
    EXPECT_LT(x[0], 0.01);  // it creeps towards the boundary
    EXPECT_TRUE(std::isfinite(rep.finalCost));
    // Started outside: nothing to do, said so.
    std::vector<double> bad = {-3.0};
    EXPECT_EQ(solve(p, bad).stop, Stop::NotFinite);
    EXPECT_EQ(bad[0], -3.0);
}

// A parameter the residuals do not depend on: the covariance is reported singular, not huge.
TEST(LevenbergMarquardt, UnobservableParameterGivesNoCovariance) {
    Problem p;
    p.parameters = 2;
    p.residuals = [](const std::vector<double>& x, std::vector<double>& r) {
        r = {x[0] - 1, x[0] - 2, x[0] - 3};
        return true;
    };
    p.jacobian = [](const std::vector<double>&, JacobianSink& sink) {
        const double J[6] = {1, 0, 1, 0, 1, 0};
        sink.add(0, 3, {0, 1}, J);
    };
    std::vector<double> x = {0, 0};
    const Report rep = solve(p, x);
    EXPECT_TRUE(rep.converged()) << rep.summary();
    EXPECT_NEAR(x[0], 2.0, 1e-6);  // the stopping tolerance is on the cost, 1e-12 relative
    EXPECT_FALSE(covariance(p, x).ok);
}

// A unit vector in the plane kept as (cos, sin) and stepped by an angle: the residuals are the
// differences to a target direction. The step has 1 parameter, the state 2.
TEST(LevenbergMarquardt, ManifoldStateThroughRetract) {
    Problem p;
    p.parameters = 1;
    const double target = 2.5;  // radians
    p.residuals = [&](const std::vector<double>& x, std::vector<double>& r) {
        r = {x[0] - std::cos(target), x[1] - std::sin(target)};
        return true;
    };
    p.jacobian = [](const std::vector<double>& x, JacobianSink& sink) {
        const double J[2] = {-x[1], x[0]};  // d(cos a, sin a) / da
        sink.add(0, 2, {0}, J);
    };
    p.retract = [](std::vector<double>& x, const std::vector<double>& d) {
        const double a = std::atan2(x[1], x[0]) + d[0];
        x = {std::cos(a), std::sin(a)};
    };
    std::vector<double> x = {1, 0};
    const Report rep = solve(p, x);
    EXPECT_TRUE(rep.converged()) << rep.summary();
    EXPECT_NEAR(std::atan2(x[1], x[0]), target, 1e-6);
    const auto J = denseJacobian(p, x), Jfd = finiteDifferenceJacobian(p, x, 1e-6);
    for (size_t i = 0; i < J.size(); ++i) EXPECT_NEAR(J[i], Jfd[i], 1e-8);
}

}  // namespace
}  // namespace mirage::lm
