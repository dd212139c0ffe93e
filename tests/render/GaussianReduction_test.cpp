// The Gaussian sum reduction of the rough-refraction pass (render/passes/rough/gsr.glsl, the
// shader's code compiled as C++): Runnalls' merge keeps the mixture's weight, mean and
// covariance; identical lobes merge into themselves; degenerate covariances (zero,
// rank-deficient, non-finite) and weights (zero, negative, huge) give finite output; the
// eigen-decomposition and the hemisphere sectors behave at their edge cases.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "render/passes/rough/GaussianReduction.h"

namespace mirage::render::gsr {
namespace {

bool finite(const GsrLobe& g) {
    return std::isfinite(g.mean.x) && std::isfinite(g.mean.y) && std::isfinite(g.cov.x) &&
           std::isfinite(g.cov.y) && std::isfinite(g.cov.z) && std::isfinite(g.weight);
}

// The mixture's moments computed directly: total weight, mean, covariance (xx, yy, xy).
GsrLobe mixtureMoments(const std::vector<GsrLobe>& lobes) {
    double w = 0, mx = 0, my = 0;
    for (const GsrLobe& g : lobes) {
        w += g.weight;
        mx += g.weight * g.mean.x;
        my += g.weight * g.mean.y;
    }
    mx /= w;
    my /= w;
    double cxx = 0, cyy = 0, cxy = 0;
    for (const GsrLobe& g : lobes) {
        const double dx = g.mean.x - mx, dy = g.mean.y - my;
        cxx += g.weight * (g.cov.x + dx * dx);
        cyy += g.weight * (g.cov.y + dy * dy);
        cxy += g.weight * (g.cov.z + dx * dy);
    }
    return gsrLobe(vec2(float(mx), float(my)), vec3(float(cxx / w), float(cyy / w), float(cxy / w)),
                   float(w));
}

TEST(GaussianReduction, MergePreservesWeightMeanAndCovariance) {
    const std::vector<GsrLobe> lobes = {
        gsrLobe(vec2(0.10f, -0.05f), vec3(0.010f, 0.004f, 0.002f), 2.0f),
        gsrLobe(vec2(-0.20f, 0.15f), vec3(0.001f, 0.020f, -0.003f), 0.5f),
        gsrLobe(vec2(0.00f, 0.30f), vec3(0.0f), 1.25f),               // a zero covariance
        gsrLobe(vec2(0.05f, 0.05f), vec3(0.004f, 0.0f, 0.0f), 3.0f),  // rank-deficient
    };
    GsrLobe acc = gsrLobe(vec2(0.0f), vec3(0.0f), 0.0f);  // the shader's empty accumulator
    for (const GsrLobe& g : lobes) acc = gsrMerge(acc, g);
    const GsrLobe want = mixtureMoments(lobes);
    EXPECT_NEAR(acc.weight, want.weight, 1e-5);
    EXPECT_NEAR(acc.mean.x, want.mean.x, 1e-6);
    EXPECT_NEAR(acc.mean.y, want.mean.y, 1e-6);
    EXPECT_NEAR(acc.cov.x, want.cov.x, 1e-6);
    EXPECT_NEAR(acc.cov.y, want.cov.y, 1e-6);
    EXPECT_NEAR(acc.cov.z, want.cov.z, 1e-6);
    // The seed's isotropic form is half the trace: k1 s1^2 + k2 s2^2 + k1 k2 |mu1 - mu2|^2 / 2.
    const GsrLobe a = gsrLobe(vec2(0.1f, 0.0f), vec3(0.01f, 0.01f, 0.0f), 1.0f);
    const GsrLobe b = gsrLobe(vec2(-0.1f, 0.2f), vec3(0.03f, 0.03f, 0.0f), 3.0f);
    const GsrLobe m = gsrMerge(a, b);
    const float seed = 0.25f * 0.01f + 0.75f * 0.03f + 0.25f * 0.75f * (0.04f + 0.04f) / 2.0f;
    EXPECT_NEAR(0.5f * (m.cov.x + m.cov.y), seed, 1e-7);
    // Order does not matter (the sequential merge is the mixture's moments).
    const GsrLobe m2 = gsrMerge(b, a);
    EXPECT_NEAR(m.mean.x, m2.mean.x, 1e-7);
    EXPECT_NEAR(m.cov.z, m2.cov.z, 1e-7);
}

TEST(GaussianReduction, IdenticalLobesMergeIntoThemselves) {
    const GsrLobe g = gsrLobe(vec2(0.12f, -0.3f), vec3(0.02f, 0.005f, 0.003f), 1.5f);
    const GsrLobe m = gsrMerge(g, g);
    EXPECT_FLOAT_EQ(m.mean.x, g.mean.x);
    EXPECT_FLOAT_EQ(m.mean.y, g.mean.y);
    EXPECT_FLOAT_EQ(m.cov.x, g.cov.x);
    EXPECT_FLOAT_EQ(m.cov.y, g.cov.y);
    EXPECT_FLOAT_EQ(m.cov.z, g.cov.z);
    EXPECT_FLOAT_EQ(m.weight, 3.0f);
    // Merging with an empty (zero-weight) lobe returns the other exactly, both ways.
    const GsrLobe empty = gsrLobe(vec2(0.0f), vec3(0.0f), 0.0f);
    for (const GsrLobe& r : {gsrMerge(empty, g), gsrMerge(g, empty)}) {
        EXPECT_EQ(r.mean, g.mean);
        EXPECT_EQ(r.cov, g.cov);
        EXPECT_EQ(r.weight, g.weight);
    }
}

TEST(GaussianReduction, DegenerateInputsGiveFiniteOutput) {
    const float inf = std::numeric_limits<float>::infinity();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const GsrLobe zero = gsrLobe(vec2(0.0f), vec3(0.0f), 0.0f);
    const GsrLobe point = gsrLobe(vec2(0.2f, 0.1f), vec3(0.0f), 1.0f);  // zero covariance
    const GsrLobe line = gsrLobe(vec2(-0.1f, 0.0f), vec3(0.0f, 0.04f, 0.0f), 1.0f);  // rank 1
    const GsrLobe bad[] = {
        gsrLobe(vec2(nan, 0.0f), vec3(0.01f), 1.0f), gsrLobe(vec2(0.0f), vec3(inf, 0, 0), 1.0f),
        gsrLobe(vec2(0.0f), vec3(0.01f), -2.0f),     gsrLobe(vec2(0.0f), vec3(0.01f), nan),
        gsrLobe(vec2(0.0f), vec3(0.01f), inf),
    };
    // Two zero-weight lobes: a finite zero-weight lobe.
    const GsrLobe zz = gsrMerge(zero, zero);
    EXPECT_TRUE(finite(zz));
    EXPECT_EQ(zz.weight, 0.0f);
    // Two zero-covariance lobes: the covariance is the spread of the means (rank 1).
    const GsrLobe pl = gsrMerge(point, gsrLobe(vec2(0.0f, 0.1f), vec3(0.0f), 1.0f));
    EXPECT_TRUE(finite(pl));
    EXPECT_NEAR(pl.cov.x, 0.01f, 1e-7);
    EXPECT_NEAR(pl.cov.y, 0.0f, 1e-9);
    const GsrLobe ln = gsrMerge(point, line);
    EXPECT_TRUE(finite(ln));
    for (const GsrLobe& b : bad) {
        const GsrLobe r = gsrMerge(point, b);
        EXPECT_TRUE(finite(r));
        if (!std::isinf(b.weight)) {
            EXPECT_EQ(r.mean, point.mean);  // the bad lobe is ignored
        }
        EXPECT_TRUE(finite(gsrMerge(b, b)));
    }
    // Eigen-decomposition: zero, rank-deficient, isotropic and (numerically) negative inputs.
    for (const vec3& c :
         {vec3(0.0f), vec3(0.04f, 0.0f, 0.0f), vec3(0.0f, 0.04f, 0.0f), vec3(0.02f, 0.02f, 0.02f),
          vec3(0.01f, 0.01f, 0.0f), vec3(-1e-9f, 0.0f, 0.0f)}) {
        const vec3 e = gsrEigen(c);
        EXPECT_TRUE(std::isfinite(e.x) && std::isfinite(e.y) && std::isfinite(e.z));
        EXPECT_GE(e.y, 0.0f);
        EXPECT_GE(e.x, e.y);
        EXPECT_NEAR(e.x + e.y, std::max(c.x + c.y, 0.0f), 1e-7);
    }
    EXPECT_NEAR(gsrEigen(vec3(0.0f, 0.04f, 0.0f)).z, 1.5707963f, 1e-6);  // major along y
    const vec3 diag = gsrEigen(vec3(0.02f, 0.02f, 0.02f));               // rank 1 along x = y
    EXPECT_NEAR(diag.x, 0.04f, 1e-7);
    EXPECT_NEAR(diag.y, 0.0f, 1e-7);
    EXPECT_NEAR(diag.z, 0.7853982f, 1e-6);
}

TEST(GaussianReduction, SectorsSplitTheHemisphereByAzimuth) {
    EXPECT_EQ(gsrSector(vec2(0.3f, 0.1f), 1), 0);
    EXPECT_EQ(gsrSector(vec2(0.0f), 4), 0);  // the centre
    // Four sectors: quadrants starting at -pi.
    EXPECT_EQ(gsrSector(vec2(-1.0f, -0.01f), 4), 0);
    EXPECT_EQ(gsrSector(vec2(0.01f, -1.0f), 4), 1);
    EXPECT_EQ(gsrSector(vec2(1.0f, 0.01f), 4), 2);
    EXPECT_EQ(gsrSector(vec2(-0.01f, 1.0f), 4), 3);
    for (int n = 1; n <= 8; ++n)
        for (float a = -3.2f; a < 3.2f; a += 0.01f) {
            const int k = gsrSector(vec2(std::cos(a), std::sin(a)), n);
            EXPECT_GE(k, 0);
            EXPECT_LT(k, n);
        }
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(gsrSector(vec2(nan, 0.0f), 4), 0);
}

}  // namespace
}  // namespace mirage::render::gsr
