// Gaussian sum reduction for rough refraction (Runnalls 2007, "Kullback-Leibler approach to
// Gaussian mixture reduction", with the rough-refraction seed's merge) and the 2x2 covariance
// helpers of the rough-refraction pass, written once in the syntax GLSL and C++ share:
// rough_refraction.frag includes it, render/passes/rough/GaussianReduction.h includes it in C++
// (glm types) so the unit tests run the code the shader runs. A lobe is a 2D Gaussian over
// slopes in a tangent plane (radians, small angles): mean, covariance (xx, yy, xy; rad^2) and a
// non-negative weight. Float literals carry the f suffix (double in C++ otherwise).
#ifndef MIRAGE_GSR_GLSL
#define MIRAGE_GSR_GLSL

// C++ defines it as `inline` (one definition in every translation unit); GLSL has no inline.
#ifndef MIRAGE_GLSL_INLINE
#define MIRAGE_GLSL_INLINE
#endif

struct GsrLobe {
    vec2 mean;     // slope (rad) in the tangent plane
    vec3 cov;      // covariance: xx, yy, xy (rad^2)
    float weight;  // >= 0
};

MIRAGE_GLSL_INLINE GsrLobe gsrLobe(vec2 mean, vec3 cov, float weight) {
    GsrLobe g;
    g.mean = mean;
    g.cov = cov;
    g.weight = weight;
    return g;
}

// A lobe with a non-finite mean or covariance, or a negative / non-finite weight, gets weight 0
// (the merge then ignores it); weights are capped at 1e30 so that their sum stays finite.
MIRAGE_GLSL_INLINE GsrLobe gsrSanitize(GsrLobe g) {
    bool finite = !any(isnan(g.mean)) && !any(isinf(g.mean)) && !any(isnan(g.cov)) &&
                  !any(isinf(g.cov));
    float w = g.weight >= 0.0f && g.weight <= 1e30f ? g.weight : (g.weight > 1e30f ? 1e30f : 0.0f);
    if (!finite) return gsrLobe(vec2(0.0f), vec3(0.0f), 0.0f);
    return gsrLobe(g.mean, g.cov, w);
}

// Runnalls' moment-preserving merge of two weighted Gaussians: w = w1 + w2, k_i = w_i / w,
//   mu = k1 mu1 + k2 mu2,  Sigma = k1 Sigma1 + k2 Sigma2 + k1 k2 (mu1 - mu2)(mu1 - mu2)^T.
// The merged mixture keeps its weight, mean and covariance (the first two moments). Half its
// trace is the seed's isotropic form sigma^2 = k1 s1^2 + k2 s2^2 + k1 k2 |mu1 - mu2|^2 / 2 (s^2
// per axis). Zero total weight returns a zero-weight lobe (finite); a zero-weight side returns
// the other exactly. Both inputs sanitised (gsrSanitize).
MIRAGE_GLSL_INLINE GsrLobe gsrMerge(GsrLobe a, GsrLobe b) {
    a = gsrSanitize(a);
    b = gsrSanitize(b);
    if (!(b.weight > 0.0f)) return a;
    if (!(a.weight > 0.0f)) return b;
    float w = a.weight + b.weight;
    float ka = a.weight / w, kb = b.weight / w;
    vec2 d = a.mean - b.mean;
    GsrLobe m;
    m.mean = ka * a.mean + kb * b.mean;
    m.cov = ka * a.cov + kb * b.cov + (ka * kb) * vec3(d.x * d.x, d.y * d.y, d.x * d.y);
    m.weight = w;
    return m;
}

// Eigen-decomposition of a symmetric 2x2 covariance (xx, yy, xy), clamped positive
// semi-definite: (major variance, minor variance, angle of the major axis from +x in radians).
// Zero, rank-deficient and isotropic covariances are exact and finite (angle 0 if isotropic).
MIRAGE_GLSL_INLINE vec3 gsrEigen(vec3 c) {
    float h = 0.5f * (c.x + c.y);
    float dd = 0.5f * (c.x - c.y);
    float r = sqrt(dd * dd + c.z * c.z);
    float angle = r > 0.0f ? 0.5f * atan(c.z, dd) : 0.0f;
    return vec3(max(h + r, 0.0f), max(h - r, 0.0f), angle);
}

// The hemisphere subdivision of GSR: n equal azimuth sectors of the tangent plane around the
// central normal (slope 0); sector of a slope, 0 for n <= 1 or a zero slope.
MIRAGE_GLSL_INLINE int gsrSector(vec2 slope, int n) {
    if (n <= 1 || !(dot(slope, slope) > 0.0f)) return 0;
    float t = atan(slope.y, slope.x) / 6.2831853f + 0.5f;  // [0, 1]
    int k = int(floor(t * float(n)));
    return k < 0 ? 0 : (k > n - 1 ? n - 1 : k);
}

#endif
