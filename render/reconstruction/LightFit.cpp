#include "render/reconstruction/LightFit.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "core/image/ImageIO.h"
#include "core/math/LevenbergMarquardt.h"

namespace mirage::reconstruction {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct TableSample {
    glm::dvec3 x;         // world
    glm::dvec3 radiance;  // linear camera units
};

glm::dvec3 directionFrom(double yaw, double pitch) {
    return {std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw)};
}

FittedSpotLight lightFromParameters(const std::vector<double>& p) {
    FittedSpotLight l;
    l.position = {p[0], p[1], p[2]};
    l.direction = directionFrom(p[3], p[4]);
    l.outerConeRad = p[5];
    l.innerConeRad = p[5] * p[6];
    return l;
}

bool admissible(const std::vector<double>& p) {
    return p[5] > 0.05 && p[5] < 1.55 && p[6] > 0.02 && p[6] < 0.98;
}

// Per channel least squares of radiance = a + b S; returns a, b (b >= 0).
void solveLinear(const std::vector<TableSample>& s, const std::vector<double>& S,
                 const std::vector<char>& used, glm::dvec3& a, glm::dvec3& b) {
    double n = 0, sS = 0, sSS = 0;
    glm::dvec3 sL(0.0), sSL(0.0);
    for (size_t i = 0; i < s.size(); ++i) {
        if (!used[i]) continue;
        n += 1, sS += S[i], sSS += S[i] * S[i];
        sL += s[i].radiance, sSL += S[i] * s[i].radiance;
    }
    const double det = n * sSS - sS * sS;
    if (n < 2 || std::abs(det) < 1e-30) {
        a = n > 0 ? sL / n : glm::dvec3(0.0);
        b = glm::dvec3(0.0);
        return;
    }
    b = glm::max((n * sSL - sS * sL) / det, glm::dvec3(0.0));
    a = (sL - b * sS) / n;
}

struct FitResult {
    std::vector<double> params;
    glm::dvec3 a{0.0}, b{0.0};
    double cost = 1e300;
};

FitResult fitFrom(const std::vector<TableSample>& samples, const std::vector<char>& used,
                  const glm::dvec3& normal, std::vector<double> x, int maxIterations) {
    const size_t n = samples.size();
    auto geometry = [&](const std::vector<double>& p, std::vector<double>& S) {
        const FittedSpotLight l = lightFromParameters(p);
        S.resize(n);
        for (size_t i = 0; i < n; ++i) S[i] = spotGeometry(l, samples[i].x, normal);
    };
    lm::Problem problem;
    problem.parameters = 7;
    problem.residuals = [&](const std::vector<double>& p, std::vector<double>& r) {
        if (!admissible(p)) return false;
        std::vector<double> S;
        geometry(p, S);
        glm::dvec3 a, b;
        solveLinear(samples, S, used, a, b);
        r.assign(3 * n, 0.0);
        for (size_t i = 0; i < n; ++i) {
            if (!used[i]) continue;
            const glm::dvec3 e = samples[i].radiance - (a + b * S[i]);
            r[3 * i] = e.x, r[3 * i + 1] = e.y, r[3 * i + 2] = e.z;
        }
        return true;
    };
    problem.jacobian = [&](const std::vector<double>& p, lm::JacobianSink& sink) {
        const std::vector<double> J = lm::finiteDifferenceJacobian(problem, p, 1e-5);
        const std::vector<int> columns{0, 1, 2, 3, 4, 5, 6};
        sink.add(0, 3 * n, columns, J.data());
    };
    lm::Options opt;
    opt.maxIterations = maxIterations;
    opt.relativeTolerance = 1e-9;
    opt.achievedTolerance = 1e-9;
    const lm::Report report = lm::solve(problem, x, opt);
    FitResult f;
    f.params = x;
    f.cost = report.finalCost;
    std::vector<double> S;
    geometry(x, S);
    solveLinear(samples, S, used, f.a, f.b);
    return f;
}

// Observed table cells, away from the objects, on a coarser grid.
std::vector<TableSample> tableSamples(const FusedGeometry& g, const LightFitOptions& o) {
    std::vector<TableSample> out;
    const TableEstimate& t = g.table;
    const int step = std::max(1, int(std::lround(o.sampleCellM / g.tableCellM)));
    for (int y = 0; y < g.tableColour.rows; y += step)
        for (int x = 0; x < g.tableColour.cols; x += step) {
            if (!g.tableObserved.at<uchar>(y, x)) continue;
            const double u = t.uMin + (x + 0.5) * g.tableCellM;
            const double v = t.vMin + (y + 0.5) * g.tableCellM;
            // The board's paper is another material than the table: it is left out of the fit.
            if (std::abs(u) < t.plane.halfU && std::abs(v) < t.plane.halfV) continue;
            const glm::dvec3 w = t.plane.toWorld({u, v, 0.0});
            bool nearObject = false;
            for (const auto& obj : g.objects) {
                const glm::dvec3 c = t.plane.toPlane(obj.centre);
                if (std::abs(u - c.x) < obj.sizeU / 2 + o.objectMarginM &&
                    std::abs(v - c.y) < obj.sizeV / 2 + o.objectMarginM)
                    nearObject = true;
            }
            if (nearObject) continue;
            const cv::Vec3f c = g.tableColour.at<cv::Vec3f>(y, x);
            out.push_back({w, {c[0], c[1], c[2]}});
        }
    return out;
}

// Starting points: above the brightest cells' centre at a few heights and offsets, shining at it.
std::vector<std::vector<double>> starts(const std::vector<TableSample>& s,
                                        const BoardPlane& plane) {
    std::vector<double> brightness;
    for (const auto& t : s) brightness.push_back(t.radiance.x + t.radiance.y + t.radiance.z);
    std::vector<double> sorted = brightness;
    std::sort(sorted.begin(), sorted.end());
    const double threshold = sorted[size_t(0.9 * double(sorted.size() - 1))];
    glm::dvec3 centre(0.0);
    int count = 0;
    for (size_t i = 0; i < s.size(); ++i)
        if (brightness[i] >= threshold) centre += s[i].x, ++count;
    centre /= double(std::max(1, count));
    std::vector<std::vector<double>> out;
    for (double height : {0.6, 1.0, 1.5})
        for (double offset : {0.0, 0.5})
            for (int side = 0; side < (offset > 0 ? 4 : 1); ++side) {
                const double angle = side * kPi / 2;
                const glm::dvec3 p =
                    centre + height * plane.normal +
                    offset * height *
                        (std::cos(angle) * plane.axisU + std::sin(angle) * plane.axisV());
                const glm::dvec3 d = glm::normalize(centre - p);
                out.push_back({p.x, p.y, p.z, std::atan2(d.x, d.z),
                               std::asin(std::clamp(d.y, -1.0, 1.0)), 0.6, 0.6});
            }
    return out;
}

}  // namespace

double spotGeometry(const FittedSpotLight& light, const glm::dvec3& x, const glm::dvec3& n) {
    const glm::dvec3 toLight = light.position - x;
    const double r2 = glm::dot(toLight, toLight);
    if (r2 <= 1e-12) return 0.0;
    const glm::dvec3 l = toLight / std::sqrt(r2);
    const double cosIncidence = glm::dot(n, l);
    if (cosIncidence <= 0) return 0.0;
    const double cosAxis = glm::dot(-l, light.direction);
    const double cosInner = std::cos(light.innerConeRad), cosOuter = std::cos(light.outerConeRad);
    const double a =
        std::clamp((cosAxis - cosOuter) / std::max(1e-3, cosInner - cosOuter), 0.0, 1.0);
    return a * a * cosIncidence / r2;
}

double dielectricSpecularAlbedo(double viewCosine, double roughness) {
    const double NdotV = std::clamp(viewCosine, 1e-4, 1.0);
    const glm::dvec3 v(std::sqrt(1 - NdotV * NdotV), 0.0, NdotV);  // normal +z
    const double a = std::max(roughness * roughness, 1e-3), a2 = a * a, k = a * 0.5;
    const int nTheta = 96, nPhi = 192;
    const double dTheta = 0.5 * kPi / nTheta, dPhi = 2 * kPi / nPhi;
    double sum = 0;
    for (int i = 0; i < nTheta; ++i) {
        const double theta = (i + 0.5) * dTheta, NdotL = std::cos(theta);
        for (int j = 0; j < nPhi; ++j) {
            const double phi = (j + 0.5) * dPhi;
            const glm::dvec3 l(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                               NdotL);
            const glm::dvec3 h = glm::normalize(l + v);
            const double NdotH = h.z, VdotH = std::max(glm::dot(v, h), 0.0);
            const double dd = NdotH * NdotH * (a2 - 1) + 1;
            const double D = a2 / (kPi * dd * dd);
            const double G = (NdotL / (NdotL * (1 - k) + k)) * (NdotV / (NdotV * (1 - k) + k));
            const double F = 0.04 + 0.96 * std::pow(1 - VdotH, 5.0);
            // BRDF x cos x solid angle (sin(theta) dTheta dPhi).
            sum += D * G * F / (4 * NdotV) * std::sin(theta) * dTheta * dPhi;
        }
    }
    // Radiance reflected under uniform radiance L_u is sum * L_u; as a share of E / pi = L_u.
    return sum;
}

glm::dvec3 environmentIrradiance(const cv::Mat& bgr, const CameraIntrinsics& camera,
                                 const Pose& T_world_camera, const glm::vec3& gain,
                                 const glm::dvec3& up) {
    // Stratified cosine-weighted directions about `up`: E = pi * mean radiance.
    const glm::dvec3 t = glm::normalize(std::abs(up.x) < 0.9 ? glm::cross(up, {1, 0, 0})
                                                             : glm::cross(up, {0, 1, 0}));
    const glm::dvec3 b = glm::cross(up, t);
    const Pose T_camera_world = T_world_camera.inverse();
    const int nr = 32, nphi = 64;
    glm::dvec3 sum(0.0);
    int seen = 0;
    for (int i = 0; i < nr; ++i)
        for (int j = 0; j < nphi; ++j) {
            const double r = std::sqrt((i + 0.5) / nr), phi = 2 * kPi * (j + 0.5) / nphi;
            const glm::dvec3 d = r * std::cos(phi) * t + r * std::sin(phi) * b +
                                 std::sqrt(std::max(0.0, 1 - r * r)) * up;
            const auto px = camera.project(T_camera_world.rotation * d);
            if (!px || px->x < 0 || px->y < 0 || px->x > bgr.cols - 1 || px->y > bgr.rows - 1)
                continue;
            const cv::Vec3b c = bgr.at<cv::Vec3b>(int(px->y + 0.5), int(px->x + 0.5));
            sum += glm::dvec3(srgbToLinear(c[2] / 255.0f) * gain.r,
                              srgbToLinear(c[1] / 255.0f) * gain.g,
                              srgbToLinear(c[0] / 255.0f) * gain.b);
            ++seen;
        }
    return seen > 0 ? kPi * sum / double(seen) : glm::dvec3(0.0);
}

LightingEstimate estimateLighting(const FusedGeometry& g,
                                  const std::optional<glm::dvec3>& environment,
                                  const LightFitOptions& o) {
    LightingEstimate e;
    const glm::dvec3 normal = g.table.plane.normal;
    const std::vector<TableSample> samples = tableSamples(g, o);
    glm::dvec3 a(0.0), b(0.0);
    if (samples.size() >= 20) {
        std::vector<char> used(samples.size(), 1);
        FitResult best;
        for (const auto& x0 : starts(samples, g.table.plane)) {
            FitResult f = fitFrom(samples, used, normal, x0, o.maxIterations / 3);
            if (f.cost < best.cost) best = f;
        }
        // Trim the cells the model cannot explain (shadows of objects, highlights) and refine.
        FittedSpotLight l = lightFromParameters(best.params);
        std::vector<double> err(samples.size());
        for (size_t i = 0; i < samples.size(); ++i)
            err[i] = glm::length(samples[i].radiance -
                                 (best.a + best.b * spotGeometry(l, samples[i].x, normal)));
        std::vector<double> sortedErr = err;
        std::sort(sortedErr.begin(), sortedErr.end());
        const double cut = 3.0 * sortedErr[sortedErr.size() / 2] + 1e-6;
        int trimmed = 0;
        for (size_t i = 0; i < samples.size(); ++i)
            if (err[i] > cut) used[i] = 0, ++trimmed;
        best = fitFrom(samples, used, normal, best.params, o.maxIterations);
        l = lightFromParameters(best.params);
        a = best.a, b = best.b;
        const int kept = int(samples.size()) - trimmed;
        l.rmsResidual = std::sqrt(best.cost / std::max(1, 3 * kept));
        l.cellsUsed = kept;
        l.cellsTrimmed = trimmed;
        // Contrast at the pool's centre: where the light's axis meets the plane.
        const double denom = glm::dot(l.direction, normal);
        if (denom < -1e-3) {
            const double s = glm::dot(g.table.plane.point - l.position, normal) / denom;
            const glm::dvec3 hit = l.position + s * l.direction;
            const double spot = glm::dot(b, glm::dvec3(1.0)) * spotGeometry(l, hit, normal);
            l.contrast = spot / std::max(1e-9, glm::dot(a, glm::dvec3(1.0)));
        }
        // A light far beyond the table or a cone near a hemisphere is the fit running away on
        // too few or too noisy cells, not a lamp: reported as none rather than confidently wrong.
        const bool plausible = glm::length(l.position - g.table.plane.point) < o.maxDistanceM &&
                               l.outerConeRad < glm::radians(80.0);
        if (l.contrast >= o.minContrast && plausible)
            e.spot = l;
        else if (!plausible)
            e.notes.push_back(
                "the spot light fit ran away (too few or too noisy table cells): "
                "no local light written");
        else
            e.notes.push_back("no local light: the table is lit evenly (spot contrast " +
                              std::to_string(l.contrast) + ")");
    } else {
        e.notes.push_back("too little of the table was observed to fit a light");
        for (const auto& s : samples) a += s.radiance / double(samples.size());
    }
    if (!e.spot) b = glm::dvec3(0.0);
    // The room's light the written material reflects specularly, as a share of E_env / pi.
    const double specular =
        o.viewCosine > 0 ? dielectricSpecularAlbedo(o.viewCosine, o.surfaceRoughness) : 0.0;
    e.specularShare = specular;
    // Albedo from a = (albedo + specular) E_env / pi.
    if (environment && glm::all(glm::greaterThan(*environment, glm::dvec3(1e-6)))) {
        e.environmentIrradiance = *environment;
        e.environmentMeasured = true;
        e.tableAlbedo = glm::clamp(kPi * a / *environment - specular, 0.01, 0.95);
        if (specular > 0)
            e.notes.push_back(fmt::format(
                "albedo: a specular share of {:.3f} of the room's light taken out (a dielectric "
                "of roughness {:.2f} seen at {:.0f} degrees from the table's normal)",
                specular, o.surfaceRoughness, glm::degrees(std::acos(o.viewCosine))));
    } else {
        e.tableAlbedo = glm::dvec3(0.5);
        e.environmentIrradiance = kPi * a / (e.tableAlbedo + specular);
        e.notes.push_back(
            "no environment camera: the table's albedo is assumed 0.5 grey, which scales every "
            "albedo and the light's intensity");
    }
    if (e.spot) e.spot->intensity = kPi * b / e.tableAlbedo;
    // The room's light on a surface tilted away from the plane's normal: the share of the upper
    // hemisphere it faces, (1 + cos) / 2.
    auto roomIrradiance = [&](const glm::dvec3& n) {
        return e.environmentIrradiance * (0.5 * (1.0 + glm::dot(n, normal)));
    };
    auto irradiance = [&](const glm::dvec3& x, const glm::dvec3& n) {
        glm::dvec3 E = roomIrradiance(n);
        if (e.spot) E += e.spot->intensity * spotGeometry(*e.spot, x, n);
        return E;
    };
    // Albedo from observed radiance L: (pi L - specular x room's light) / irradiance.
    auto albedoFrom = [&](const glm::dvec3& L, const glm::dvec3& x, const glm::dvec3& n) {
        return (kPi * L - specular * roomIrradiance(n)) / irradiance(x, n);
    };
    // The table's albedo texture: albedoFrom the observed radiance per cell; unobserved cells
    // take the median albedo.
    e.tableAlbedoTexture = cv::Mat(g.tableColour.size(), CV_32FC3,
                                   cv::Scalar(e.tableAlbedo.x, e.tableAlbedo.y, e.tableAlbedo.z));
    for (int y = 0; y < g.tableColour.rows; ++y)
        for (int x = 0; x < g.tableColour.cols; ++x) {
            if (!g.tableObserved.at<uchar>(y, x)) continue;
            const glm::dvec3 w =
                g.table.plane.toWorld({g.table.uMin + (x + 0.5) * g.tableCellM,
                                       g.table.vMin + (y + 0.5) * g.tableCellM, 0});
            const cv::Vec3f c = g.tableColour.at<cv::Vec3f>(y, x);
            const glm::dvec3 rho =
                glm::clamp(albedoFrom(glm::dvec3(c[0], c[1], c[2]), w, normal), 0.0, 1.0);
            e.tableAlbedoTexture.at<cv::Vec3f>(y, x) =
                cv::Vec3f(float(rho.x), float(rho.y), float(rho.z));
        }
    for (const auto& obj : g.objects) {
        std::vector<double> channel[3];
        for (size_t i = 0; i < obj.samplePoints.size(); ++i) {
            const glm::dvec3 x(obj.samplePoints[i]);
            const glm::dvec3 n = glm::normalize(glm::dvec3(obj.sampleNormals[i]));
            if (glm::dot(irradiance(x, n), glm::dvec3(1.0)) < 1e-6) continue;
            const glm::dvec3 rho = albedoFrom(glm::dvec3(obj.sampleColours[i]), x, n);
            for (int c = 0; c < 3; ++c) channel[c].push_back(rho[c]);
        }
        glm::dvec3 rho = e.tableAlbedo;
        for (int c = 0; c < 3; ++c)
            if (!channel[c].empty()) {
                auto mid = channel[c].begin() + long(channel[c].size() / 2);
                std::nth_element(channel[c].begin(), mid, channel[c].end());
                rho[c] = std::clamp(*mid, 0.01, 0.95);
            }
        e.objectAlbedo.push_back(rho);
    }
    return e;
}

}  // namespace mirage::reconstruction
