#include "core/camera/CameraModel.h"

#include <algorithm>
#include <cmath>

#include "core/Error.h"

namespace mirage {

DistortionModel distortionModelFromName(const std::string& name) {
    if (name == "plumb_bob" || name == "pinhole" || name == "rational_polynomial" ||
        name == "brown_conrady")
        return DistortionModel::BrownConrady;
    if (name == "fisheye" || name == "equidistant" || name == "kannala_brandt")
        return DistortionModel::KannalaBrandt;
    throw Error("unknown distortion model '" + name +
                "' (use plumb_bob for pinhole + Brown-Conrady, fisheye for Kannala-Brandt)");
}

const char* distortionModelName(DistortionModel m) {
    return m == DistortionModel::KannalaBrandt ? "fisheye" : "plumb_bob";
}

bool CameraIntrinsics::isValid() const {
    auto ok = [](double v) { return std::isfinite(v); };
    for (double d : distortion)
        if (!ok(d)) return false;
    return width > 0 && height > 0 && ok(fx) && ok(fy) && fx > 0 && fy > 0 && ok(cx) && ok(cy);
}

glm::dvec2 CameraIntrinsics::distortNormalized(const glm::dvec2& xy) const {
    const double x = xy.x, y = xy.y;
    if (model == DistortionModel::BrownConrady) {
        const double k1 = coeff(0), k2 = coeff(1), p1 = coeff(2), p2 = coeff(3), k3 = coeff(4);
        const double r2 = x * x + y * y;
        const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
        return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
                y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
    }
    // Kannala-Brandt on the ideal point (x, y) = tan(theta) * unit direction in the image plane.
    const double r = std::sqrt(x * x + y * y);
    if (r < 1e-12) return xy;
    const double theta = std::atan(r);
    const double t2 = theta * theta;
    const double thetaD =
        theta * (1 + t2 * (coeff(0) + t2 * (coeff(1) + t2 * (coeff(2) + t2 * coeff(3)))));
    return xy * (thetaD / r);
}

std::optional<glm::dvec2> CameraIntrinsics::project(const glm::dvec3& p) const {
    glm::dvec2 d;
    if (model == DistortionModel::BrownConrady) {
        if (!(p.z > 1e-12)) return std::nullopt;
        d = distortNormalized({p.x / p.z, p.y / p.z});
    } else {
        // Work from the angle directly so that rays at and beyond 90 degrees stay defined.
        const double rxy = std::sqrt(p.x * p.x + p.y * p.y);
        const double theta = std::atan2(rxy, p.z);
        if (!(theta <= maxFisheyeTheta)) return std::nullopt;
        if (rxy < 1e-15) {
            d = {0.0, 0.0};
        } else {
            const double t2 = theta * theta;
            const double thetaD =
                theta * (1 + t2 * (coeff(0) + t2 * (coeff(1) + t2 * (coeff(2) + t2 * coeff(3)))));
            d = glm::dvec2(p.x, p.y) * (thetaD / rxy);
        }
    }
    glm::dvec2 px{fx * d.x + cx, fy * d.y + cy};
    if (!std::isfinite(px.x) || !std::isfinite(px.y)) return std::nullopt;
    return px;
}

std::optional<glm::dvec2> CameraIntrinsics::projectWithJacobian(const glm::dvec3& p,
                                                                glm::dmat3x2& J) const {
    if (model != DistortionModel::BrownConrady) {
        const auto p0 = project(p);
        if (!p0) return std::nullopt;
        for (int a = 0; a < 3; ++a) {
            glm::dvec3 q = p;
            const double h = 1e-6 * std::max(1e-3, std::abs(p.z));
            q[a] += h;
            const auto p1 = project(q);
            if (!p1) return std::nullopt;
            J[a] = (*p1 - *p0) / h;
        }
        return p0;
    }
    // The projection of project() and distortNormalized(), written out so that the distortion
    // terms serve the pixel and its derivatives (the pose solver's hot path).
    if (!(p.z > 1e-12)) return std::nullopt;
    const double k1 = coeff(0), k2 = coeff(1), p1 = coeff(2), p2 = coeff(3), k3 = coeff(4);
    // x, y divided as project() divides them: the same pixel to the last bit.
    const double iz = 1.0 / p.z, x = p.x / p.z, y = p.y / p.z;
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const glm::dvec2 px{fx * (x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)) + cx,
                        fy * (y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y) + cy};
    if (!std::isfinite(px.x) || !std::isfinite(px.y)) return std::nullopt;
    const double dRadial = k1 + r2 * (2 * k2 + 3 * k3 * r2);  // d radial / d r2
    // Derivatives of the distorted point (u, v) by the normalised point (x, y).
    const double dudx = radial + 2 * x * x * dRadial + 2 * p1 * y + 6 * p2 * x;
    const double dudy = 2 * x * y * dRadial + 2 * p1 * x + 2 * p2 * y;
    const double dvdx = dudy;
    const double dvdy = radial + 2 * y * y * dRadial + 6 * p1 * y + 2 * p2 * x;
    // (x, y) = (X / Z, Y / Z).
    J[0] = {fx * dudx * iz, fy * dvdx * iz};
    J[1] = {fx * dudy * iz, fy * dvdy * iz};
    J[2] = {-fx * (dudx * x + dudy * y) * iz, -fy * (dvdx * x + dvdy * y) * iz};
    return px;
}

std::optional<glm::dvec3> CameraIntrinsics::unproject(const glm::dvec2& pixel) const {
    const glm::dvec2 d{(pixel.x - cx) / fx, (pixel.y - cy) / fy};
    if (model == DistortionModel::KannalaBrandt) {
        // Solve thetaD = theta (1 + k1 t^2 + ...) for theta by Newton's method.
        const double thetaD = std::sqrt(d.x * d.x + d.y * d.y);
        if (thetaD < 1e-15) return glm::dvec3(0, 0, 1);
        double theta = std::min(thetaD, maxFisheyeTheta);
        bool converged = false;
        for (int it = 0; it < 30; ++it) {
            const double t2 = theta * theta;
            const double f =
                theta * (1 + t2 * (coeff(0) + t2 * (coeff(1) + t2 * (coeff(2) + t2 * coeff(3))))) -
                thetaD;
            const double df =
                1 +
                t2 * (3 * coeff(0) + t2 * (5 * coeff(1) + t2 * (7 * coeff(2) + t2 * 9 * coeff(3))));
            if (std::abs(df) < 1e-12) break;
            const double step = f / df;
            theta -= step;
            if (std::abs(step) < 1e-14) {
                converged = true;
                break;
            }
        }
        if (!converged || !(theta >= 0) || theta > maxFisheyeTheta + 1e-9) return std::nullopt;
        const double s = std::sin(theta) / thetaD;
        return glm::normalize(glm::dvec3(d.x * s, d.y * s, std::cos(theta)));
    }
    // Brown-Conrady: Gauss-Newton on distortNormalized(u) = d with a numeric Jacobian, which
    // converges where OpenCV's fixed-point iteration can oscillate for strong distortion.
    glm::dvec2 u = d;
    bool converged = false;
    for (int it = 0; it < 40; ++it) {
        const glm::dvec2 r = distortNormalized(u) - d;
        if (glm::dot(r, r) < 1e-24) {
            converged = true;
            break;
        }
        const double h = 1e-7;
        const glm::dvec2 jx = (distortNormalized(u + glm::dvec2(h, 0)) - distortNormalized(u)) / h;
        const glm::dvec2 jy = (distortNormalized(u + glm::dvec2(0, h)) - distortNormalized(u)) / h;
        const double det = jx.x * jy.y - jy.x * jx.y;
        if (std::abs(det) < 1e-12) break;
        const glm::dvec2 step{(jy.y * r.x - jy.x * r.y) / det, (-jx.y * r.x + jx.x * r.y) / det};
        u -= step;
        if (!std::isfinite(u.x) || !std::isfinite(u.y)) break;
    }
    if (!converged) return std::nullopt;
    return glm::normalize(glm::dvec3(u.x, u.y, 1.0));
}

}  // namespace mirage
