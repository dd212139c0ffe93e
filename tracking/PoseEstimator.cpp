#include "tracking/PoseEstimator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include <opencv2/calib3d.hpp>

#include "core/Error.h"

namespace mirage::tracking {

const char* trackingStateName(TrackingState s) {
    switch (s) {
        case TrackingState::Ok:
            return "ok";
        case TrackingState::NoTags:
            return "no_tags";
        case TrackingState::TagsTooSmall:
            return "tags_too_small";
        case TrackingState::TooBlurred:
            return "too_blurred";
        case TrackingState::Ambiguous:
            return "ambiguous";
        case TrackingState::Lost:
            return "lost";
        case TrackingState::Uncertain:
            return "uncertain";
    }
    return "?";
}

namespace {

struct Observation {
    int tagId = 0;
    std::array<glm::dvec3, 4> world{};  // corners in the world
    std::array<glm::dvec2, 4> pixels{};
    double sidePx = 0;        // shortest side in the image
    double edgeWidthPx = -1;  // TagDetection::edgeWidthPx
    double sizeM = 0;
    Pose T_world_tag;
};

constexpr double kMissPenaltyPx = 1000.0;  // residual of a corner the pose puts out of view

// Pixel residuals of all corners of `obs` under T_world_camera (8 per tag).
void residuals(const CameraIntrinsics& cam, const Pose& T_world_camera,
               const std::vector<const Observation*>& obs, std::vector<double>& r) {
    r.clear();
    const Pose T_camera_world = T_world_camera.inverse();
    for (const Observation* o : obs) {
        for (int k = 0; k < 4; ++k) {
            const auto px = cam.project(T_camera_world * o->world[size_t(k)]);
            if (px) {
                r.push_back(px->x - o->pixels[size_t(k)].x);
                r.push_back(px->y - o->pixels[size_t(k)].y);
            } else {
                r.push_back(kMissPenaltyPx);
                r.push_back(kMissPenaltyPx);
            }
        }
    }
}

double rmsOf(const std::vector<double>& r) {
    if (r.empty()) return 0;
    double s = 0;
    for (double v : r) s += v * v;
    return std::sqrt(s / (double(r.size()) / 2.0));  // per corner (2D error)
}

// The pose perturbed by x = (rotation vector in world axes, camera-centre offset in metres).
Pose perturbed(const Pose& p, const double* x) {
    const glm::dvec3 w(x[0], x[1], x[2]);
    const double a = glm::length(w);
    Pose q = p;
    if (a > 0) q.rotation = glm::normalize(glm::angleAxis(a, w / a) * p.rotation);
    q.translation += glm::dvec3(x[3], x[4], x[5]);
    return q;
}

struct Fit {
    Pose pose;
    double rms = 1e9;
    std::array<double, 36> covariance{};
    // (J^T J)^-1 at the solution and the sum of squared residuals (set with the covariance).
    std::array<double, 36> normalInverse{};
    double cost = 0;
    double robustSigma = 0;  // 1.4826 x the median absolute residual (pixels)
    // Sensitivities to corner errors shared within a tag (correlatedTerms).
    std::array<double, 36> tagScale{}, tagShift{};
    std::array<double, 6> commonScale{};
    bool ok = false;
};

// Jacobian rows (2 per corner) of the pixel residuals w.r.t. x = (world-frame rotation vector of
// the camera, camera centre): X_c = R^T (X_w - c), so dX_c/dw = R^T [X_w - c]_x and
// dX_c/dc = -R^T; the 2x3 projection Jacobian dpx/dX_c is taken by forward differences per point
// (3 projections; the lens models stay in one place, CameraModel.cpp).
void jacobian(const CameraIntrinsics& cam, const Pose& T_world_camera,
              const std::vector<const Observation*>& obs, std::vector<double>& J) {
    J.assign(obs.size() * 8 * 6, 0.0);
    const glm::dmat3 Rt = glm::transpose(T_world_camera.rotationMatrix());
    const glm::dvec3 c = T_world_camera.translation;
    size_t row = 0;
    for (const Observation* o : obs) {
        for (int k = 0; k < 4; ++k, row += 2) {
            const glm::dvec3 d = o->world[size_t(k)] - c;
            const glm::dvec3 Xc = Rt * d;
            const auto p0 = cam.project(Xc);
            if (!p0) continue;  // penalty residual: constant, zero gradient
            glm::dmat3x2 dp;    // 3 columns of d(px)/dX_c
            bool ok = true;
            for (int a = 0; a < 3 && ok; ++a) {
                glm::dvec3 Xh = Xc;
                const double h = 1e-6 * std::max(1e-3, std::abs(Xc.z));
                Xh[a] += h;
                const auto p1 = cam.project(Xh);
                if (!p1)
                    ok = false;
                else
                    dp[a] = (*p1 - *p0) / h;
            }
            if (!ok) continue;
            // dX_c/dw: R^T [d]_x  (columns: R^T (e_i x d) ... = R^T * skew(d) with sign below).
            // X_c(w) = R^T exp(-w) d ~ R^T (d - w x d) = R^T (d + d x w) -> dX_c/dw = R^T [d]_x.
            const glm::dmat3 skew(0, d.z, -d.y, -d.z, 0, d.x, d.y, -d.x, 0);  // columns of [d]_x
            const glm::dmat3 dXdw = Rt * skew;
            const glm::dmat3 dXdc = -Rt;
            for (int j = 0; j < 6; ++j) {
                const glm::dvec3 col = j < 3 ? dXdw[j] : dXdc[j - 3];
                const glm::dvec2 g = dp * col;
                J[row * 6 + size_t(j)] = g.x;
                J[(row + 1) * 6 + size_t(j)] = g.y;
            }
        }
    }
}

// The sensitivities of the pose to corner errors that are shared within a tag (docs/tracking.md,
// "Uncertainty and the ok state"): per tag, J^T u with u the corners' image displacement of a
// scale change of the tag by 1 px per corner (outwards from its centre), and of a shift by 1 px
// in x and in y. Accumulated as sum g g^T (per-tag terms) and sum g (the scale term common to
// all tags of the frame).
void correlatedTerms(const std::vector<double>& J, const std::vector<const Observation*>& obs,
                     Fit& f) {
    f.tagScale = {};
    f.tagShift = {};
    f.commonScale = {};
    size_t row = 0;
    for (const Observation* o : obs) {
        glm::dvec2 centre(0.0);
        for (const auto& p : o->pixels) centre += 0.25 * p;
        std::array<double, 6> gs{}, gx{}, gy{};
        for (int k = 0; k < 4; ++k, row += 2) {
            const glm::dvec2 d = o->pixels[size_t(k)] - centre;
            const glm::dvec2 u = d / std::max(1e-9, glm::length(d));
            for (int a = 0; a < 6; ++a) {
                const double jx = J[row * 6 + size_t(a)], jy = J[(row + 1) * 6 + size_t(a)];
                gs[size_t(a)] += jx * u.x + jy * u.y;
                gx[size_t(a)] += jx;
                gy[size_t(a)] += jy;
            }
        }
        for (int a = 0; a < 6; ++a) {
            f.commonScale[size_t(a)] += gs[size_t(a)];
            for (int b = 0; b < 6; ++b) {
                f.tagScale[size_t(a * 6 + b)] += gs[size_t(a)] * gs[size_t(b)];
                f.tagShift[size_t(a * 6 + b)] +=
                    gx[size_t(a)] * gx[size_t(b)] + gy[size_t(a)] * gy[size_t(b)];
            }
        }
    }
}

// Levenberg-Marquardt on the pixel reprojection error of all corners of `obs`.
Fit refine(const CameraIntrinsics& cam, const Pose& start,
           const std::vector<const Observation*>& obs, bool withCovariance,
           int maxIterations = 30) {
    Fit f;
    f.pose = start;
    std::vector<double> r, r2, J;
    residuals(cam, f.pose, obs, r);
    double cost = 0;
    for (double v : r) cost += v * v;
    double lambda = 1e-4;
    const size_t m = r.size();
    auto normalEquations = [&](cv::Matx66d& A, cv::Vec6d& g) {
        jacobian(cam, f.pose, obs, J);
        A = cv::Matx66d::zeros();
        g = cv::Vec6d();
        for (size_t i = 0; i < m; ++i) {
            const double* Ji = &J[i * 6];
            for (int a = 0; a < 6; ++a) {
                g[a] += Ji[a] * r[i];
                for (int b = a; b < 6; ++b) A(a, b) += Ji[a] * Ji[b];
            }
        }
        for (int a = 0; a < 6; ++a)
            for (int b = 0; b < a; ++b) A(a, b) = A(b, a);
    };
    for (int it = 0; it < maxIterations; ++it) {
        cv::Matx66d A;
        cv::Vec6d g;
        normalEquations(A, g);
        bool improved = false, converged = false;
        for (int tries = 0; tries < 8 && !improved; ++tries) {
            cv::Matx66d Ad = A;
            for (int a = 0; a < 6; ++a) Ad(a, a) += lambda * std::max(A(a, a), 1e-12);
            cv::Vec6d dx;
            if (!cv::solve(Ad, -g, dx, cv::DECOMP_CHOLESKY)) {
                lambda *= 10;
                continue;
            }
            // Predicted decrease of the Gauss-Newton model; below 1e-6 of the cost we are done (the
            // remaining step moves the pose by ~1e-3 of its noise).
            const double predicted = -(2 * g.dot(dx) + dx.dot(A * dx));
            if (predicted < 1e-6 * cost + 1e-20) {
                converged = true;
                break;
            }
            const Pose cand = perturbed(f.pose, dx.val);
            residuals(cam, cand, obs, r2);
            double c2 = 0;
            for (double v : r2) c2 += v * v;
            if (std::isfinite(c2) && c2 < cost) {
                f.pose = cand;
                r.swap(r2);
                cost = c2;
                lambda = std::max(lambda * 0.2, 1e-9);
                improved = true;
            } else {
                lambda *= 10;
            }
        }
        if (!improved || converged) break;
    }
    f.rms = rmsOf(r);
    f.ok = f.pose.isFinite() && std::isfinite(f.rms);
    if (withCovariance && f.ok && m > 6) {
        cv::Matx66d A;
        cv::Vec6d g;
        normalEquations(A, g);
        // Residual variance per coordinate, m - 6 degrees of freedom.
        const double sigma2 = cost / double(m - 6);
        cv::Matx66d inv;
        if (cv::invert(A, inv, cv::DECOMP_SVD) != 0) {
            for (int a = 0; a < 6; ++a)
                for (int b = 0; b < 6; ++b) {
                    f.covariance[size_t(a * 6 + b)] = inv(a, b) * sigma2;
                    f.normalInverse[size_t(a * 6 + b)] = inv(a, b);
                }
            f.cost = cost;
            // Robust noise scale: the median absolute residual (a few tags with damaged
            // corners should not set the noise of all).
            std::vector<double> a(r.size());
            for (size_t i = 0; i < r.size(); ++i) a[i] = std::abs(r[i]);
            std::nth_element(a.begin(), a.begin() + long(a.size() / 2), a.end());
            f.robustSigma = 1.4826 * a[a.size() / 2];
            correlatedTerms(J, obs, f);
        }
    }
    return f;
}

// Corner RMS of one tag (as rmsOf(residuals(...)) for that tag alone, without allocating: it is
// called for every candidate pose and tag).
double tagRms(const CameraIntrinsics& cam, const Pose& T_world_camera, const Observation& o) {
    const Pose T_camera_world = T_world_camera.inverse();
    double s = 0;
    for (int k = 0; k < 4; ++k) {
        const auto px = cam.project(T_camera_world * o.world[size_t(k)]);
        if (px) {
            const glm::dvec2 d = *px - o.pixels[size_t(k)];
            s += glm::dot(d, d);
        } else {
            s += 2 * kMissPenaltyPx * kMissPenaltyPx;
        }
    }
    return std::sqrt(s / 4.0);
}

// The pose covariance under the corner noise model of PoseEstimatorOptions:
//   C = N^-1 (sigma^2 N + s_t^2 S_tag + h^2 H_tag + s_c^2 g g^T) N^-1 k^2,  N = J^T J,
// sigma^2 the independent corner noise (residuals pooled with the prior sigma0 by tag size and
// blur), s_t / h the per-tag scale / shift error and s_c the scale error common to all tags
// (corner errors that move a tag's corners together: blur mixing the payload into the border,
// clipping, compression), each proportional to sigma0; k the inflation.
std::array<double, 36> modelCovariance(const Fit& f, const std::vector<const Observation*>& obs,
                                       const PoseEstimatorOptions& o) {
    std::array<double, 36> c{};
    if (obs.empty() || f.normalInverse[0] <= 0) return c;
    double prior2 = 0;
    for (const Observation* t : obs) {
        const double blur = std::max(0.0, t->edgeWidthPx - 2.2);
        const double s0 = o.cornerNoisePx + o.cornerNoiseSidePx / std::max(1.0, t->sidePx) +
                          o.cornerNoiseBlur * blur * blur;
        prior2 += s0 * s0 / double(obs.size());
    }
    const double dof = 8.0 * double(obs.size()) - 6.0;
    // The residuals' robust mean square (median absolute residual, 2N values) stands for the
    // sum of squares: 2N rho^2 ~ sum r^2, whose expectation is (2N - 6) sigma^2.
    const double sumSq = 8.0 * double(obs.size()) * f.robustSigma * f.robustSigma;
    const double sigma2 =
        (sumSq + o.cornerNoisePriorWeight * prior2) / (dof + o.cornerNoisePriorWeight);
    const double st2 = o.tagScaleNoise * o.tagScaleNoise * prior2;
    const double sh2 = o.tagShiftNoise * o.tagShiftNoise * prior2;
    const double sc2 = o.commonScaleNoise * o.commonScaleNoise * prior2;
    cv::Matx66d Ninv, M;
    for (int a = 0; a < 6; ++a)
        for (int b = 0; b < 6; ++b) {
            const size_t i = size_t(a * 6 + b);
            Ninv(a, b) = f.normalInverse[i];
            M(a, b) = st2 * f.tagScale[i] + sh2 * f.tagShift[i] +
                      sc2 * f.commonScale[size_t(a)] * f.commonScale[size_t(b)];
        }
    const cv::Matx66d C =
        (Ninv * sigma2 + Ninv * M * Ninv) * (o.covarianceInflation * o.covarianceInflation);
    for (int a = 0; a < 6; ++a)
        for (int b = 0; b < 6; ++b) c[size_t(a * 6 + b)] = 0.5 * (C(a, b) + C(b, a));
    return c;
}

std::string idList(const std::vector<int>& ids) {
    std::string s;
    for (size_t i = 0; i < ids.size(); ++i)
        s += (i == 0 ? "" : (i + 1 == ids.size() ? " and " : ", ")) + std::to_string(ids[i]);
    return s;
}

bool samePose(const Pose& a, const Pose& b, double scale, double maxDeg = 1.0,
              double maxRel = 0.02) {
    return rotationAngleBetween(a.rotation, b.rotation) < glm::radians(maxDeg) &&
           glm::length(a.translation - b.translation) < maxRel * scale;
}

}  // namespace

PoseEstimator::PoseEstimator(Board board, CameraIntrinsics camera, PoseEstimatorOptions options)
    : board_(std::move(board)), camera_(std::move(camera)), options_(options) {
    if (!camera_.isValid()) throw Error("pose estimator: invalid camera intrinsics");
    if (board_.tags.empty()) throw Error("pose estimator: the board has no tags");
}

PoseEstimate PoseEstimator::estimate(const std::vector<TagDetection>& detections,
                                     const std::optional<Pose>& prior,
                                     const std::optional<Pose>& initial) const {
    PoseEstimate out;
    char buf[256];
    // 1. Board tags seen; a tag id seen twice cannot be told apart: both dropped.
    std::map<int, int> seen;
    for (const auto& d : detections)
        if (board_.find(d.id)) ++seen[d.id];
    std::vector<Observation> obs;
    int tooSmall = 0;
    for (const auto& d : detections) {
        const BoardTag* tag = board_.find(d.id);
        if (!tag) continue;
        if (seen[d.id] > 1) {
            out.tagsRejected.push_back(d.id);
            continue;
        }
        Observation o;
        o.tagId = d.id;
        o.world = tag->cornersInWorld();
        o.pixels = d.corners;
        o.sizeM = tag->size;
        o.edgeWidthPx = d.edgeWidthPx;
        o.T_world_tag = tag->T_world_tag;
        o.sidePx = 1e9;
        for (int k = 0; k < 4; ++k)
            o.sidePx = std::min(o.sidePx,
                                glm::length(d.corners[size_t(k)] - d.corners[size_t((k + 1) % 4)]));
        if (o.sidePx < options_.minTagSidePx) {
            ++tooSmall;
            out.tagsRejected.push_back(d.id);
            continue;
        }
        obs.push_back(o);
    }
    if (obs.empty()) {
        if (tooSmall > 0) {
            out.state = TrackingState::TagsTooSmall;
            std::snprintf(buf, sizeof buf, "%d board tag(s) seen, all under %.0f px", tooSmall,
                          options_.minTagSidePx);
            out.reason = buf;
        } else {
            out.state = TrackingState::NoTags;
            out.reason = seen.empty() ? "no board tag detected" : "only duplicated tag ids seen";
        }
        return out;
    }

    // 2. Candidates: both IPPE solutions of each of the largest tags (their corners are the most
    // precise; a few are enough to contain the right pose even with an outlier tag among them),
    // as T_world_camera.
    std::vector<const Observation*> initTags;
    for (const auto& o : obs) initTags.push_back(&o);
    std::sort(initTags.begin(), initTags.end(),
              [](const Observation* a, const Observation* b) { return a->sidePx > b->sidePx; });
    const size_t maxInit = initial ? 1 : size_t(std::max(1, options_.maxInitTags));
    if (initTags.size() > maxInit) initTags.resize(maxInit);
    std::vector<Pose> candidates;
    if (initial && initial->isFinite()) candidates.push_back(*initial);
    const double maxInitZ = std::cos(glm::radians(options_.maxInitAngleDeg));
    for (const Observation* op : initTags) {
        const Observation& o = *op;
        std::vector<cv::Point2d> img;
        for (const auto& p : o.pixels) {
            const auto ray = camera_.unproject(p);
            if (!ray || ray->z < maxInitZ) break;
            img.emplace_back(ray->x / ray->z, ray->y / ray->z);
        }
        if (img.size() != 4) continue;
        std::vector<cv::Point3d> objp;
        for (const auto& c : BoardTag::cornersInTag(o.sizeM)) objp.emplace_back(c.x, c.y, c.z);
        std::vector<cv::Mat> rvecs, tvecs;
        try {
            cv::solvePnPGeneric(objp, img, cv::Matx33d::eye(), cv::noArray(), rvecs, tvecs, false,
                                cv::SOLVEPNP_IPPE_SQUARE);
        } catch (const cv::Exception&) {
            continue;
        }
        for (size_t s = 0; s < rvecs.size(); ++s) {
            cv::Matx33d R;
            cv::Rodrigues(rvecs[s], R);
            glm::dmat3 Rg;
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b) Rg[b][a] = R(a, b);  // glm is column-major
            const cv::Vec3d t(tvecs[s]);
            const Pose T_camera_tag = Pose::fromRotationTranslation(Rg, {t[0], t[1], t[2]});
            if (!(t[2] > 0)) continue;  // tag behind the camera
            const Pose cand = o.T_world_tag * T_camera_tag.inverse();
            if (cand.isFinite()) candidates.push_back(cand);
        }
    }
    if (candidates.empty()) {
        out.state = TrackingState::Lost;
        out.reason = "no tag gave an initial pose (IPPE failed)";
        return out;
    }

    // 3. Score candidates by supporting tags, then error; refine the best few.
    struct Scored {
        Pose pose;
        int support = 0;
        double cost = 0;
    };
    std::vector<Scored> scored;
    for (const auto& c : candidates) {
        Scored s{c, 0, 0};
        for (const auto& o : obs) {
            const double e = tagRms(camera_, c, o);
            const double thr = std::max(options_.candidateInlierPx, 0.15 * o.sidePx);
            if (e < thr) ++s.support;
            s.cost += std::min(e, thr);
        }
        scored.push_back(s);
    }
    std::sort(scored.begin(), scored.end(), [](const Scored& a, const Scored& b) {
        return a.support != b.support ? a.support > b.support : a.cost < b.cost;
    });

    // Camera-to-board distance: the scale of "the same translation" when comparing poses (the
    // world origin may be anywhere relative to the board).
    double sceneScale = 1e-3;
    for (const auto& c : candidates)
        sceneScale =
            std::max(sceneScale, glm::length(c.translation - obs[0].T_world_tag.translation));

    struct Refined {
        Fit fit;
        std::vector<const Observation*> inliers;
    };
    auto refineWithRejection = [&](const Pose& start) {
        Refined best;
        std::vector<const Observation*> use;
        for (const auto& o : obs) {
            const double thr = std::max(options_.candidateInlierPx, 0.15 * o.sidePx);
            if (tagRms(camera_, start, o) < 4 * thr) use.push_back(&o);
        }
        if (use.empty()) return best;
        Fit f = refine(camera_, start, use, false);
        for (int round = 0; round < 3 && f.ok; ++round) {
            std::vector<double> rmsPerTag;
            for (const auto& o : obs) rmsPerTag.push_back(tagRms(camera_, f.pose, o));
            std::vector<double> sorted;
            for (size_t i = 0; i < obs.size(); ++i)
                if (std::find(use.begin(), use.end(), &obs[i]) != use.end())
                    sorted.push_back(rmsPerTag[i]);
            std::nth_element(sorted.begin(), sorted.begin() + long(sorted.size() / 2),
                             sorted.end());
            const double thr = std::max(options_.outlierTagRmsPx, 4 * sorted[sorted.size() / 2]);
            std::vector<const Observation*> next;
            for (size_t i = 0; i < obs.size(); ++i)
                if (rmsPerTag[i] < thr) next.push_back(&obs[i]);
            if (next.empty()) break;
            if (next == use) break;
            use = next;
            f = refine(camera_, f.pose, use, false);
        }
        best.fit = f;
        best.inliers = use;
        return best;
    };

    std::vector<Refined> refined;
    // At most 4 refinements: the best-supported candidate, and distinct others for the ambiguity
    // test below (most candidates of a multi-tag view converge to the same pose).
    int refinements = 0;
    for (size_t i = 0; i < scored.size() && refined.size() < 3 && refinements < 4; ++i) {
        // A candidate that explains fewer than half as many tags as the best one cannot win and
        // is no serious alternative (the classic flip of the largest tag is checked below).
        if (2 * scored[i].support < scored[0].support) break;
        bool dup = false;
        // An unrefined candidate near an already refined pose would converge to it: single-tag
        // IPPE poses scatter by a few degrees around the multi-tag optimum (the flipped
        // solution of a tilted tag lies tens of degrees away).
        for (const auto& r : refined)
            dup = dup || samePose(r.fit.pose, scored[i].pose, sceneScale, 5.0, 0.05);
        if (dup) continue;
        ++refinements;
        Refined r = refineWithRejection(scored[i].pose);
        if (!r.fit.ok) continue;
        bool dupAfter = false;
        for (const auto& q : refined)
            dupAfter = dupAfter || samePose(q.fit.pose, r.fit.pose, sceneScale);
        if (!dupAfter) refined.push_back(std::move(r));
    }
    if (refined.empty()) {
        out.state = TrackingState::Lost;
        out.reason = "pose refinement failed";
        return out;
    }
    std::sort(refined.begin(), refined.end(), [](const Refined& a, const Refined& b) {
        return a.inliers.size() != b.inliers.size() ? a.inliers.size() > b.inliers.size()
                                                    : a.fit.rms < b.fit.rms;
    });
    Refined& best = refined[0];
    for (const auto* o : best.inliers) out.tagsUsed.push_back(o->tagId);
    for (const auto& o : obs)
        if (std::find(best.inliers.begin(), best.inliers.end(), &o) == best.inliers.end()) {
            out.tagsRejected.push_back(o.tagId);
            out.tagsDisagreeing.push_back(o.tagId);
        }
    const Fit finalFit = refine(camera_, best.fit.pose, best.inliers, true);
    out.pose = finalFit.pose;
    out.rmsPx = finalFit.rms;
    out.covariance = modelCovariance(finalFit, best.inliers, options_);
    {
        glm::dvec3 centre(0.0);
        for (const auto* o : best.inliers) centre += o->T_world_tag.translation;
        centre /= double(best.inliers.size());
        out.distanceM = glm::length(finalFit.pose.translation - centre);
    }

    // 4. Ambiguity: the best distinct alternative, refined on the same tags.
    std::optional<Pose> altPose;
    for (size_t i = 1; i < refined.size(); ++i) {
        const Fit alt = refine(camera_, refined[i].fit.pose, best.inliers, false);
        if (!alt.ok || samePose(alt.pose, finalFit.pose, sceneScale)) continue;
        if (out.alternativeRmsPx < 0 || alt.rms < out.alternativeRmsPx) {
            out.alternativeRmsPx = alt.rms;
            altPose = alt.pose;
        }
    }
    // Also the flipped IPPE solution of the largest used tag (the classic planar ambiguity),
    // which may not have made it into the refined set.
    {
        const Observation* big = best.inliers[0];
        for (const auto* o : best.inliers)
            if (o->sidePx > big->sidePx) big = o;
        int attempts = 0;
        std::vector<Pose> tried;
        for (const auto& s : scored) {
            if (attempts >= 2) break;
            if (samePose(s.pose, finalFit.pose, sceneScale)) continue;
            bool seenBefore = false;
            for (const auto& t : tried) seenBefore = seenBefore || samePose(t, s.pose, sceneScale);
            if (seenBefore) continue;
            if (tagRms(camera_, s.pose, *big) >
                std::max(options_.candidateInlierPx, 0.15 * big->sidePx))
                continue;
            tried.push_back(s.pose);
            ++attempts;
            const Fit alt = refine(camera_, s.pose, best.inliers, false);
            if (!alt.ok || samePose(alt.pose, finalFit.pose, sceneScale)) continue;
            if (out.alternativeRmsPx < 0 || alt.rms < out.alternativeRmsPx) {
                out.alternativeRmsPx = alt.rms;
                altPose = alt.pose;
            }
        }
    }

    // 5. Consistency: each tag against the others. Tags that the board pose of the others does
    // not explain were dropped above; when they are not outnumbered by the tags used, no subset
    // can be trusted: most likely the board file does not describe the printed board.
    if (!out.tagsDisagreeing.empty() && out.tagsDisagreeing.size() >= out.tagsUsed.size()) {
        out.state = TrackingState::Lost;
        out.reason = (out.tagsDisagreeing.size() == 1 ? "tag " : "tags ") +
                     idList(out.tagsDisagreeing) +
                     (out.tagsDisagreeing.size() == 1 ? " disagrees" : " disagree") + " with tag" +
                     (out.tagsUsed.size() == 1 ? " " : "s ") + idList(out.tagsUsed) +
                     ": is the board file right?";
        return out;
    }
    std::string dropped;
    if (!out.tagsDisagreeing.empty())
        dropped = "; dropped tag" + std::string(out.tagsDisagreeing.size() == 1 ? " " : "s ") +
                  idList(out.tagsDisagreeing) + " (disagree with the others)";

    if (!(finalFit.rms <= options_.maxRmsPx)) {
        out.state = TrackingState::Lost;
        std::snprintf(buf, sizeof buf, "reprojection RMS %.2f px over %zu tag(s) exceeds %.2f px",
                      finalFit.rms, best.inliers.size(), options_.maxRmsPx);
        out.reason = buf;
        return out;
    }
    // 6. The pose is ok only if its uncertainty is within the bounds (any state decided below
    // that would be ok becomes uncertain otherwise).
    auto settle = [&](const std::string& what) {
        const double sr = out.sigmaRotDeg(), sp = out.sigmaPosM();
        const double maxPos = options_.okMaxSigmaPosFraction * out.distanceM;
        char b[400];
        if (sr > options_.okMaxSigmaRotDeg || sp > maxPos) {
            out.state = TrackingState::Uncertain;
            std::snprintf(b, sizeof b,
                          "%s; 1 sigma %.2f deg / %.1f mm (%.2f %% of %.2f m) exceeds %.2f deg / "
                          "%.2f %%",
                          what.c_str(), sr, 1e3 * sp, 100 * sp / out.distanceM, out.distanceM,
                          options_.okMaxSigmaRotDeg, 100 * options_.okMaxSigmaPosFraction);
        } else {
            out.state = TrackingState::Ok;
            std::snprintf(b, sizeof b, "%s; 1 sigma %.3f deg / %.2f mm", what.c_str(), sr,
                          1e3 * sp);
        }
        out.reason = b + dropped;
        return out;
    };
    const bool clearlyBetter =
        !altPose || (out.alternativeRmsPx >= options_.ambiguityRatio * finalFit.rms &&
                     out.alternativeRmsPx - finalFit.rms >= options_.ambiguityMinGapPx);
    if (clearlyBetter) {
        if (altPose)
            std::snprintf(buf, sizeof buf, "%zu tag(s), RMS %.2f px, alternative %.2f px",
                          best.inliers.size(), finalFit.rms, out.alternativeRmsPx);
        else
            std::snprintf(buf, sizeof buf, "%zu tag(s), RMS %.2f px, no alternative pose",
                          best.inliers.size(), finalFit.rms);
        return settle(buf);
    }
    // Ambiguous by error alone: let the previous pose decide if it clearly can.
    if (prior) {
        const double dBest = rotationAngleBetween(prior->rotation, finalFit.pose.rotation);
        const double dAlt = rotationAngleBetween(prior->rotation, altPose->rotation);
        const double maxRot = glm::radians(options_.priorMaxRotationDeg);
        const Pose* chosen = nullptr;
        if (dBest <= maxRot && dAlt >= 2 * dBest) chosen = &finalFit.pose;
        if (dAlt <= maxRot && dBest >= 2 * dAlt) chosen = &*altPose;
        if (chosen) {
            const bool flipped = chosen != &finalFit.pose;
            if (flipped) {
                const Fit f = refine(camera_, *chosen, best.inliers, true);
                out.pose = f.pose;
                out.alternativeRmsPx = finalFit.rms;
                out.rmsPx = f.rms;
                out.covariance = modelCovariance(f, best.inliers, options_);
            }
            std::snprintf(buf, sizeof buf,
                          "%zu tag(s), RMS %.2f px; planar ambiguity (alternative %.2f px) "
                          "resolved by the previous pose",
                          best.inliers.size(), out.rmsPx, out.alternativeRmsPx);
            return settle(buf);
        }
    }
    out.state = TrackingState::Ambiguous;
    std::snprintf(buf, sizeof buf,
                  "planar ambiguity: two poses fit %zu tag(s) (RMS %.2f vs %.2f px)%s",
                  best.inliers.size(), finalFit.rms, out.alternativeRmsPx,
                  prior ? " and the previous pose does not decide"
                        : ", no well-determined recent pose to decide");
    out.reason = buf + dropped;
    return out;
}

}  // namespace mirage::tracking
