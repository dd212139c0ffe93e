#include "tracking/PoseEstimator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>

#include <opencv2/calib3d.hpp>

#include "core/Error.h"
#include "core/math/LevenbergMarquardt.h"

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
    lm::Report report;
};

// Jacobian rows (2 per corner) of the pixel residuals w.r.t. x = (world-frame rotation vector of
// the camera, camera centre): X_c = R^T (X_w - c), so dX_c/dw = R^T [X_w - c]_x and
// dX_c/dc = -R^T; the 2x3 projection Jacobian dpx/dX_c comes from the camera model
// (CameraIntrinsics::projectWithJacobian: closed form for the pinhole model).
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
            glm::dmat3x2 dp;  // 3 columns of d(px)/dX_c
            // Out of view: penalty residual, constant, zero gradient.
            if (!cam.projectWithJacobian(Xc, dp)) continue;
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

// The pose as a least-squares problem for core/math/LevenbergMarquardt.h (PoseEstimator.h,
// poseLeastSquares).
// The Jacobian buffer of one refinement and the state it was last evaluated at: the solver's
// last evaluation is usually at the solution (it stops when the step it predicts from there is
// negligible), so the covariance reuses it instead of evaluating it again.
struct JacobianCache {
    std::vector<double> J;
    std::vector<double> x;
};

lm::Problem poseProblem(const CameraIntrinsics& cam, const std::vector<const Observation*>& obs,
                        JacobianCache* cache = nullptr) {
    lm::Problem p;
    p.parameters = 6;
    p.residuals = [&cam, &obs](const std::vector<double>& x, std::vector<double>& r) {
        residuals(cam, poseOfState(x), obs, r);
        return true;
    };
    p.jacobian = [&cam, &obs, cache](const std::vector<double>& x, lm::JacobianSink& sink) {
        std::vector<double> local;
        std::vector<double>& J = cache ? cache->J : local;
        jacobian(cam, poseOfState(x), obs, J);
        if (cache) cache->x = x;
        static const std::vector<int> kColumns = {0, 1, 2, 3, 4, 5};
        sink.add(0, J.size() / 6, kColumns, J.data());
    };
    p.retract = [](std::vector<double>& x, const std::vector<double>& dx) {
        x = poseState(perturbed(poseOfState(x), dx.data()));
    };
    return p;
}

// Levenberg-Marquardt on the pixel reprojection error of all corners of `obs`. It stops when the
// predicted decrease is below 1e-6 of the cost: the remaining step moves the pose by ~1e-3 of its
// noise.
Fit refine(const CameraIntrinsics& cam, const Pose& start,
           const std::vector<const Observation*>& obs, bool withCovariance,
           int maxIterations = 30) {
    JacobianCache cache;
    const lm::Problem problem = poseProblem(cam, obs, &cache);
    lm::Options o;
    o.maxIterations = maxIterations;
    o.relativeTolerance = 1e-6;
    o.achievedTolerance = 0;
    o.initialLambda = 1e-4;
    std::vector<double> x = poseState(start);
    Fit f;
    f.report = lm::solve(problem, x, o);
    f.pose = poseOfState(x);
    const size_t corners = f.report.residualCount / 2;
    f.rms = corners ? std::sqrt(f.report.finalCost / double(corners)) : 0.0;
    f.ok = f.pose.isFinite() && std::isfinite(f.rms);
    if (withCovariance && f.ok && f.report.residualCount > 6) {
        // The residuals and the solver's last Jacobian (at the solution when it converged)
        // serve the normal equations, the robust noise scale and the shared-corner-error terms
        // (lm::covariance would evaluate the Jacobian again: this runs once per frame in the
        // tracking loop).
        std::vector<double> r;
        residuals(cam, f.pose, obs, r);
        std::vector<double>& J = cache.J;
        if (cache.x != x) jacobian(cam, f.pose, obs, J);
        cv::Matx66d A = cv::Matx66d::zeros();
        double cost = 0;
        for (size_t i = 0; i < r.size(); ++i) {
            const double* Ji = &J[i * 6];
            cost += r[i] * r[i];
            for (int u = 0; u < 6; ++u)
                for (int v = u; v < 6; ++v) A(u, v) += Ji[u] * Ji[v];
        }
        for (int u = 0; u < 6; ++u)
            for (int v = 0; v < u; ++v) A(u, v) = A(v, u);
        cv::Matx66d inv;
        if (cv::invert(A, inv, cv::DECOMP_SVD) != 0) {
            const double sigma2 = cost / double(r.size() - 6);  // residual variance
            for (int u = 0; u < 6; ++u)
                for (int v = 0; v < 6; ++v) {
                    f.normalInverse[size_t(u * 6 + v)] = inv(u, v);
                    f.covariance[size_t(u * 6 + v)] = inv(u, v) * sigma2;
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

// Corner RMS of one tag (the RMS of residuals(...) for that tag alone, without allocating: it is
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
//   C = N^-1 (sigma^2 N + sigma^2 (a^2 - 1) H_tag / 4 + s_t^2 S_tag + h^2 H_tag + s_c^2 g g^T)
//       N^-1 k^2,  N = J^T J,  k = k0 (1 + k_b b),
// sigma^2 the independent corner noise (residuals pooled with the prior sigma0 by tag size and
// blur), a the tag centre's share of it (sigma^2 H_tag / 4 is what independent noise puts on the
// tags' centres; since a <= 1 the sum stays positive semi-definite), s_t / h the per-tag scale /
// shift error and s_c the scale error common to all tags
// (corner errors that move a tag's corners together: blur mixing the payload into the border,
// clipping, compression), each proportional to sigma0; k the inflation, growing with the tags'
// mean blur b (edge width beyond 2.2 px): a motion blur stretches every tag along one direction,
// an error none of the modes above (all isotropic) holds.
std::array<double, 36> modelCovariance(const Fit& f, const std::vector<const Observation*>& obs,
                                       const PoseEstimatorOptions& o) {
    std::array<double, 36> c{};
    if (obs.empty() || f.normalInverse[0] <= 0) return c;
    double prior2 = 0, meanBlur = 0;
    for (const Observation* t : obs) {
        const double blur = std::max(0.0, t->edgeWidthPx - 2.2);
        meanBlur += blur / double(obs.size());
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
    // The centre of a tag errs less than its corners: its variance is tagCentreNoise^2 of what
    // independent corner noise gives it (the shift mode of each tag's corners, J^T P J = H / 4;
    // measured: the tag centres' error is 0.4-0.5 of the independent corner noise).
    const double centre2 = sigma2 * (o.tagCentreNoise * o.tagCentreNoise - 1.0) / 4.0;
    cv::Matx66d Ninv, M;
    for (int a = 0; a < 6; ++a)
        for (int b = 0; b < 6; ++b) {
            const size_t i = size_t(a * 6 + b);
            Ninv(a, b) = f.normalInverse[i];
            M(a, b) = st2 * f.tagScale[i] + (sh2 + centre2) * f.tagShift[i] +
                      sc2 * f.commonScale[size_t(a)] * f.commonScale[size_t(b)];
        }
    // With one tag the prior already dominates sigma^2 (2 degrees of freedom), and the Monte
    // Carlo shows its blurred poses inside their ellipsoids without the blur term.
    const double k = o.covarianceInflation *
                     (1.0 + (obs.size() > 1 ? o.covarianceBlurInflation * meanBlur : 0.0));
    const cv::Matx66d C = (Ninv * sigma2 + Ninv * M * Ninv) * (k * k);
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

// A tag supports a pose if its corners reproject within this (pixels).
double inlierThreshold(const PoseEstimatorOptions& o, const Observation& obs) {
    return std::max(o.candidateInlierPx, 0.15 * obs.sidePx);
}

// Step 1. The board tags seen; a tag id seen twice cannot be told apart: both dropped; tags
// under minTagSidePx are dropped. If none is left, `out` gets the state and reason.
std::vector<Observation> observations(const Board& board, const PoseEstimatorOptions& options,
                                      const std::vector<TagDetection>& detections,
                                      PoseEstimate& out) {
    std::map<int, int> seen;
    for (const auto& d : detections)
        if (board.find(d.id)) ++seen[d.id];
    std::vector<Observation> obs;
    int tooSmall = 0;
    for (const auto& d : detections) {
        const BoardTag* tag = board.find(d.id);
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
        if (o.sidePx < options.minTagSidePx) {
            ++tooSmall;
            out.tagsRejected.push_back(d.id);
            continue;
        }
        obs.push_back(o);
    }
    if (obs.empty()) {
        if (tooSmall > 0) {
            out.state = TrackingState::TagsTooSmall;
            char buf[128];
            std::snprintf(buf, sizeof buf, "%d board tag(s) seen, all under %.0f px", tooSmall,
                          options.minTagSidePx);
            out.reason = buf;
        } else {
            out.state = TrackingState::NoTags;
            out.reason = seen.empty() ? "no board tag detected" : "only duplicated tag ids seen";
        }
    }
    return obs;
}

// Step 2. Candidates: both IPPE solutions of each of the largest tags (their corners are the most
// precise; a few are enough to contain the right pose even with an outlier tag among them), as
// T_world_camera; `initial` first if given (then only the largest tag's solutions are added).
std::vector<Pose> initialCandidates(const CameraIntrinsics& camera,
                                    const PoseEstimatorOptions& options,
                                    const std::vector<Observation>& obs,
                                    const std::optional<Pose>& initial) {
    std::vector<const Observation*> initTags;
    for (const auto& o : obs) initTags.push_back(&o);
    std::sort(initTags.begin(), initTags.end(),
              [](const Observation* a, const Observation* b) { return a->sidePx > b->sidePx; });
    const size_t maxInit = initial ? 1 : size_t(std::max(1, options.maxInitTags));
    if (initTags.size() > maxInit) initTags.resize(maxInit);
    std::vector<Pose> candidates;
    if (initial && initial->isFinite()) candidates.push_back(*initial);
    const double maxInitZ = std::cos(glm::radians(options.maxInitAngleDeg));
    for (const Observation* op : initTags) {
        const Observation& o = *op;
        std::vector<cv::Point2d> img;
        for (const auto& p : o.pixels) {
            const auto ray = camera.unproject(p);
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
    return candidates;
}

struct Scored {
    Pose pose;
    int support = 0;
    double cost = 0;
};

// Step 3. Candidates by supporting tags, then by error (best first).
std::vector<Scored> scoreCandidates(const CameraIntrinsics& camera,
                                    const PoseEstimatorOptions& options,
                                    const std::vector<Pose>& candidates,
                                    const std::vector<Observation>& obs) {
    std::vector<Scored> scored;
    for (const auto& c : candidates) {
        Scored s{c, 0, 0};
        for (const auto& o : obs) {
            const double e = tagRms(camera, c, o);
            const double thr = inlierThreshold(options, o);
            if (e < thr) ++s.support;
            s.cost += std::min(e, thr);
        }
        scored.push_back(s);
    }
    std::sort(scored.begin(), scored.end(), [](const Scored& a, const Scored& b) {
        return a.support != b.support ? a.support > b.support : a.cost < b.cost;
    });
    return scored;
}

struct Refined {
    Fit fit;
    std::vector<const Observation*> inliers;
};

// The refinements (without covariance) of one estimate, by start pose and tag set: the ambiguity
// test (step 5) refines from candidates that step 4 often refined already on the same tags, and
// a refinement is a pure function of those, so the earlier result is the answer. Each costs
// several evaluations of every corner's projection and Jacobian.
class RefinementMemo {
public:
    Fit refine(const CameraIntrinsics& camera, const Pose& start,
               const std::vector<const Observation*>& use) {
        for (const auto& e : entries_)
            if (e.use == use && sameBits(e.start, start)) return e.fit;
        Fit f = mirage::tracking::refine(camera, start, use, false);
        entries_.push_back({start, use, f});
        return f;
    }

private:
    static bool sameBits(const Pose& a, const Pose& b) {
        return a.translation == b.translation && a.rotation == b.rotation;
    }
    struct Entry {
        Pose start;
        std::vector<const Observation*> use;
        Fit fit;
    };
    std::vector<Entry> entries_;
};

// Refinement from `start` on the tags near it, then up to 3 rounds of dropping tags whose RMS
// exceeds max(outlierTagRmsPx, 4 x the median) and refining again.
Refined refineWithRejection(const CameraIntrinsics& camera, const PoseEstimatorOptions& options,
                            const std::vector<Observation>& obs, const Pose& start,
                            RefinementMemo& memo) {
    Refined best;
    std::vector<const Observation*> use;
    for (const auto& o : obs)
        if (tagRms(camera, start, o) < 4 * inlierThreshold(options, o)) use.push_back(&o);
    if (use.empty()) return best;
    Fit f = memo.refine(camera, start, use);
    for (int round = 0; round < 3 && f.ok; ++round) {
        std::vector<double> rmsPerTag;
        for (const auto& o : obs) rmsPerTag.push_back(tagRms(camera, f.pose, o));
        std::vector<double> sorted;
        for (size_t i = 0; i < obs.size(); ++i)
            if (std::find(use.begin(), use.end(), &obs[i]) != use.end())
                sorted.push_back(rmsPerTag[i]);
        std::nth_element(sorted.begin(), sorted.begin() + long(sorted.size() / 2), sorted.end());
        const double thr = std::max(options.outlierTagRmsPx, 4 * sorted[sorted.size() / 2]);
        std::vector<const Observation*> next;
        for (size_t i = 0; i < obs.size(); ++i)
            if (rmsPerTag[i] < thr) next.push_back(&obs[i]);
        if (next.empty()) break;
        if (next == use) break;
        use = next;
        f = memo.refine(camera, f.pose, use);
    }
    best.fit = f;
    best.inliers = use;
    return best;
}

// Step 4. Refines the best-supported candidate and distinct others (for the ambiguity test):
// at most 4 refinements, at most 3 distinct results, best first (most inlier tags, then RMS).
std::vector<Refined> refineCandidates(const CameraIntrinsics& camera,
                                      const PoseEstimatorOptions& options,
                                      const std::vector<Scored>& scored,
                                      const std::vector<Observation>& obs, double sceneScale,
                                      RefinementMemo& memo) {
    std::vector<Refined> refined;
    int refinements = 0;
    for (size_t i = 0; i < scored.size() && refined.size() < 3 && refinements < 4; ++i) {
        // A candidate that explains fewer than half as many tags as the best one cannot win and
        // is no serious alternative (the classic flip of the largest tag is checked later).
        if (2 * scored[i].support < scored[0].support) break;
        bool dup = false;
        // An unrefined candidate near an already refined pose would converge to it: single-tag
        // IPPE poses scatter by a few degrees around the multi-tag optimum (the flipped
        // solution of a tilted tag lies tens of degrees away).
        for (const auto& r : refined)
            dup = dup || samePose(r.fit.pose, scored[i].pose, sceneScale, 5.0, 0.05);
        if (dup) continue;
        ++refinements;
        Refined r = refineWithRejection(camera, options, obs, scored[i].pose, memo);
        if (!r.fit.ok) continue;
        bool dupAfter = false;
        for (const auto& q : refined)
            dupAfter = dupAfter || samePose(q.fit.pose, r.fit.pose, sceneScale);
        if (!dupAfter) refined.push_back(std::move(r));
    }
    std::sort(refined.begin(), refined.end(), [](const Refined& a, const Refined& b) {
        return a.inliers.size() != b.inliers.size() ? a.inliers.size() > b.inliers.size()
                                                    : a.fit.rms < b.fit.rms;
    });
    return refined;
}

struct Alternative {
    std::optional<Pose> pose;
    double rmsPx = -1;  // -1: none
};

// Step 5. The best distinct alternative to `chosen` on the same tags: the other refined poses,
// and the flipped IPPE solution of the largest used tag (the classic planar ambiguity), which
// may not have made it into the refined set.
Alternative bestAlternative(const CameraIntrinsics& camera, const PoseEstimatorOptions& options,
                            const std::vector<Refined>& refined, const std::vector<Scored>& scored,
                            const Pose& chosen, double sceneScale, RefinementMemo& memo) {
    const std::vector<const Observation*>& inliers = refined[0].inliers;
    Alternative alt;
    auto consider = [&](const Pose& start) {
        const Fit f = memo.refine(camera, start, inliers);
        if (!f.ok || samePose(f.pose, chosen, sceneScale)) return;
        if (alt.rmsPx < 0 || f.rms < alt.rmsPx) {
            alt.rmsPx = f.rms;
            alt.pose = f.pose;
        }
    };
    for (size_t i = 1; i < refined.size(); ++i) consider(refined[i].fit.pose);
    const Observation* big = inliers[0];
    for (const auto* o : inliers)
        if (o->sidePx > big->sidePx) big = o;
    int attempts = 0;
    std::vector<Pose> tried;
    for (const auto& s : scored) {
        if (attempts >= 2) break;
        if (samePose(s.pose, chosen, sceneScale)) continue;
        bool seenBefore = false;
        for (const auto& t : tried) seenBefore = seenBefore || samePose(t, s.pose, sceneScale);
        if (seenBefore) continue;
        if (tagRms(camera, s.pose, *big) > inlierThreshold(options, *big)) continue;
        tried.push_back(s.pose);
        ++attempts;
        consider(s.pose);
    }
    return alt;
}

}  // namespace

std::vector<double> poseState(const Pose& p) {
    return {p.translation.x, p.translation.y, p.translation.z, p.rotation.w,
            p.rotation.x,    p.rotation.y,    p.rotation.z};
}

Pose poseOfState(const std::vector<double>& x) {
    Pose p;
    p.translation = {x[0], x[1], x[2]};
    p.rotation = glm::dquat(x[3], x[4], x[5], x[6]);
    return p;
}

lm::Problem poseLeastSquares(const Board& board, const CameraIntrinsics& camera,
                             const std::vector<TagDetection>& detections) {
    struct Data {
        CameraIntrinsics camera;
        std::vector<Observation> obs;
        std::vector<const Observation*> use;
    };
    auto d = std::make_shared<Data>();
    d->camera = camera;
    PoseEstimatorOptions all;
    all.minTagSidePx = 0;
    PoseEstimate unused;
    d->obs = observations(board, all, detections, unused);
    for (const auto& o : d->obs) d->use.push_back(&o);
    lm::Problem inner = poseProblem(d->camera, d->use);
    lm::Problem p = inner;
    p.residuals = [d, inner](const std::vector<double>& x, std::vector<double>& r) {
        return inner.residuals(x, r);
    };
    p.jacobian = [d, inner](const std::vector<double>& x, lm::JacobianSink& sink) {
        inner.jacobian(x, sink);
    };
    return p;
}

PoseEstimator::PoseEstimator(Board board, CameraIntrinsics camera, PoseEstimatorOptions options)
    : board_(std::move(board)), camera_(std::move(camera)), options_(options) {
    if (!camera_.isValid()) throw Error("pose estimator: invalid camera intrinsics");
    if (board_.tags.empty()) throw Error("pose estimator: the board has no tags");
}

PoseEstimate PoseEstimator::estimate(const std::vector<TagDetection>& detections,
                                     const std::optional<Pose>& prior,
                                     const std::optional<Pose>& initial) const {
    PoseEstimate out;
    const std::vector<Observation> obs = observations(board_, options_, detections, out);
    if (obs.empty()) return out;

    const std::vector<Pose> candidates = initialCandidates(camera_, options_, obs, initial);
    if (candidates.empty()) {
        out.state = TrackingState::Lost;
        out.reason = "no tag gave an initial pose (IPPE failed)";
        return out;
    }
    const std::vector<Scored> scored = scoreCandidates(camera_, options_, candidates, obs);

    // Camera-to-board distance: the scale of "the same translation" when comparing poses (the
    // world origin may be anywhere relative to the board).
    double sceneScale = 1e-3;
    for (const auto& c : candidates)
        sceneScale =
            std::max(sceneScale, glm::length(c.translation - obs[0].T_world_tag.translation));

    RefinementMemo memo;
    const std::vector<Refined> refined =
        refineCandidates(camera_, options_, scored, obs, sceneScale, memo);
    if (refined.empty()) {
        out.state = TrackingState::Lost;
        out.reason = "pose refinement failed";
        return out;
    }
    const Refined& best = refined[0];
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

    const Alternative alt =
        bestAlternative(camera_, options_, refined, scored, finalFit.pose, sceneScale, memo);
    out.alternativeRmsPx = alt.rmsPx;

    // Step 6. The state: lost if the tags disagree or the fit is poor; ok if the alternative is
    // clearly worse or the previous pose decides between them and the uncertainty is within the
    // bounds (else uncertain); else ambiguous.
    char buf[256];

    // Consistency: each tag against the others. Tags that the board pose of the others does
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
    // The pose is ok only if its uncertainty is within the bounds (any state decided below that
    // would be ok becomes uncertain otherwise).
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
        !alt.pose || (alt.rmsPx >= options_.ambiguityRatio * finalFit.rms &&
                      alt.rmsPx - finalFit.rms >= options_.ambiguityMinGapPx);
    if (clearlyBetter) {
        if (alt.pose)
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
        const double dAlt = rotationAngleBetween(prior->rotation, alt.pose->rotation);
        const double maxRot = glm::radians(options_.priorMaxRotationDeg);
        const Pose* chosen = nullptr;
        if (dBest <= maxRot && dAlt >= 2 * dBest) chosen = &finalFit.pose;
        if (dAlt <= maxRot && dBest >= 2 * dAlt) chosen = &*alt.pose;
        if (chosen) {
            if (chosen != &finalFit.pose) {
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
