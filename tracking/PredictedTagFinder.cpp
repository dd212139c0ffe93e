#include "tracking/PredictedTagFinder.h"

#include <algorithm>
#include <cmath>

#include "core/Error.h"
#include "tracking/ImageLine.h"
#include "tracking/TagFamily.h"

namespace mirage::tracking {

namespace {

// Bilinear 8-bit level at (x, y), OpenCV pixel convention; false outside the image.
bool sampleLevel(const cv::Mat& grey, double x, double y, double& v) {
    const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
    if (x0 < 0 || y0 < 0 || x0 + 1 >= grey.cols || y0 + 1 >= grey.rows) return false;
    const double fx = x - x0, fy = y - y0;
    const uint8_t* r0 = grey.ptr<uint8_t>(y0);
    const uint8_t* r1 = grey.ptr<uint8_t>(y0 + 1);
    v = (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) +
        fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
    return true;
}

// Total-least-squares line through points (unweighted); RMS distance of the points to it.
ImageLine fitLine(const std::vector<glm::dvec2>& pts, double& rms) {
    glm::dvec2 mean(0.0);
    for (const auto& p : pts) mean += p;
    mean /= double(pts.size());
    double sxx = 0, sxy = 0, syy = 0;
    for (const auto& p : pts) {
        const glm::dvec2 d = p - mean;
        sxx += d.x * d.x;
        sxy += d.x * d.y;
        syy += d.y * d.y;
    }
    const double angle = 0.5 * std::atan2(2 * sxy, sxx - syy);
    ImageLine l{mean, {std::cos(angle), std::sin(angle)}};
    const glm::dvec2 n(-l.dir.y, l.dir.x);
    double s = 0;
    for (const auto& p : pts) {
        const double d = glm::dot(p - mean, n);
        s += d * d;
    }
    rms = std::sqrt(s / double(pts.size()));
    return l;
}

// Homography of the unit square onto a quad: (0,0) -> q[0], (1,0) -> q[1], (1,1) -> q[2],
// (0,1) -> q[3] (closed form, Heckbert's square-to-quad mapping).
struct SquareToQuad {
    double a, b, c, d, e, f, g, h;
    explicit SquareToQuad(const std::array<glm::dvec2, 4>& q) {
        const double sx = q[0].x - q[1].x + q[2].x - q[3].x;
        const double sy = q[0].y - q[1].y + q[2].y - q[3].y;
        const double dx1 = q[1].x - q[2].x, dx2 = q[3].x - q[2].x;
        const double dy1 = q[1].y - q[2].y, dy2 = q[3].y - q[2].y;
        const double den = dx1 * dy2 - dx2 * dy1;
        g = std::abs(den) > 1e-12 ? (sx * dy2 - dx2 * sy) / den : 0.0;
        h = std::abs(den) > 1e-12 ? (dx1 * sy - sx * dy1) / den : 0.0;
        a = q[1].x - q[0].x + g * q[1].x;
        b = q[3].x - q[0].x + h * q[3].x;
        c = q[0].x;
        d = q[1].y - q[0].y + g * q[1].y;
        e = q[3].y - q[0].y + h * q[3].y;
        f = q[0].y;
    }
    glm::dvec2 operator()(double u, double v) const {
        const double w = g * u + h * v + 1.0;
        return {(a * u + b * v + c) / w, (d * u + e * v + f) / w};
    }
};

// Correction of predicted image positions from the tags found so far: identity, then the mean
// shift (one tag), then a least-squares affine map (three tags or more; 2D, pixels).
class ImageCorrection {
public:
    void fit(const std::vector<glm::dvec2>& from, const std::vector<glm::dvec2>& to) {
        const size_t n = from.size();
        if (n < 4) return;
        glm::dvec2 mf(0.0), mt(0.0);
        for (size_t i = 0; i < n; ++i) {
            mf += from[i];
            mt += to[i];
        }
        mf /= double(n);
        mt /= double(n);
        centre_ = mf;
        target_ = mt;
        affine_ = false;
        if (n < 12) return;
        // Normal equations of to - mt = M (from - mf), for the two rows of M.
        double sxx = 0, sxy = 0, syy = 0, ux = 0, uy = 0, vx = 0, vy = 0;
        for (size_t i = 0; i < n; ++i) {
            const glm::dvec2 f = from[i] - mf, t = to[i] - mt;
            sxx += f.x * f.x;
            sxy += f.x * f.y;
            syy += f.y * f.y;
            ux += t.x * f.x;
            uy += t.x * f.y;
            vx += t.y * f.x;
            vy += t.y * f.y;
        }
        const double det = sxx * syy - sxy * sxy;
        // Points (nearly) on a line: the affine map is not determined across it.
        if (!(det > 1e-6 * (sxx + syy) * (sxx + syy))) return;
        m00_ = (ux * syy - uy * sxy) / det;
        m01_ = (uy * sxx - ux * sxy) / det;
        m10_ = (vx * syy - vy * sxy) / det;
        m11_ = (vy * sxx - vx * sxy) / det;
        affine_ = true;
    }
    bool affine() const { return affine_; }
    glm::dvec2 operator()(const glm::dvec2& p) const {
        const glm::dvec2 f = p - centre_;
        if (!affine_) return target_ + f;
        return target_ + glm::dvec2(m00_ * f.x + m01_ * f.y, m10_ * f.x + m11_ * f.y);
    }

private:
    glm::dvec2 centre_{0.0}, target_{0.0};
    bool affine_ = false;
    double m00_ = 1, m01_ = 0, m10_ = 0, m11_ = 1;
};

}  // namespace

PredictedTagFinder::PredictedTagFinder(const Board& board, CameraIntrinsics camera,
                                       TagPredictionOptions options)
    : camera_(std::move(camera)), options_(options) {
    const TagFamily family(board.family);
    widthAtBorder_ = family.widthAtBorder();
    totalWidth_ = family.totalWidth();
    for (const auto& t : board.tags) {
        TagModel m;
        m.id = t.id;
        m.world = t.cornersInWorld();
        m.centre = t.T_world_tag.translation;
        m.normal = t.T_world_tag.rotation * glm::dvec3(0, 0, 1);
        const cv::Mat img = family.codeImage(t.id);
        m.pattern.assign(img.datastart, img.dataend);
        tags_.push_back(std::move(m));
    }
}

const PredictedTagFinder::TagModel* PredictedTagFinder::model(int id) const {
    for (const auto& m : tags_)
        if (m.id == id) return &m;
    return nullptr;
}

bool PredictedTagFinder::verify(const cv::Mat& grey, int id,
                                const std::array<glm::dvec2, 4>& corners, int* innerErrors,
                                int* outerErrors, double* contrast) const {
    const TagModel* m = model(id);
    if (!m || grey.type() != CV_8UC1) return false;
    // Unit square over the detection corners: (0,0) top-left = corner 3, (1,0) top-right =
    // corner 2, (1,1) bottom-right = corner 1, (0,1) bottom-left = corner 0 (Board.h).
    const SquareToQuad H({corners[3], corners[2], corners[1], corners[0]});
    const int n = totalWidth_;
    const int offset = (totalWidth_ - widthAtBorder_) / 2;
    thread_local std::vector<double> levels;
    levels.assign(size_t(n * n), 0.0);
    double sumW = 0, sumB = 0;
    int nW = 0, nB = 0;
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
            const double u = (c - offset + 0.5) / widthAtBorder_;
            const double v = (r - offset + 0.5) / widthAtBorder_;
            const glm::dvec2 p = H(u, v);
            double level = 0;
            if (!sampleLevel(grey, p.x, p.y, level)) return false;
            levels[size_t(r * n + c)] = level;
            if (m->pattern[size_t(r * n + c)] > 127) {
                sumW += level;
                ++nW;
            } else {
                sumB += level;
                ++nB;
            }
        }
    if (nW == 0 || nB == 0) return false;
    const double white = sumW / nW, black = sumB / nB;
    const double mid = 0.5 * (white + black);
    int inner = 0, outer = 0;
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
            const bool expectWhite = m->pattern[size_t(r * n + c)] > 127;
            const bool isWhite = levels[size_t(r * n + c)] > mid;
            if (expectWhite == isWhite) continue;
            const bool inside = r >= offset && r < offset + widthAtBorder_ && c >= offset &&
                                c < offset + widthAtBorder_;
            ++(inside ? inner : outer);
        }
    if (innerErrors) *innerErrors = inner;
    if (outerErrors) *outerErrors = outer;
    if (contrast) *contrast = white - black;
    return white - black >= options_.minContrastLevels && inner <= options_.maxInnerCellErrors &&
           outer <= options_.maxOuterCellErrors;
}

PredictedTagFinder::Outcome PredictedTagFinder::follow(const cv::Mat& grey, const TagModel& m,
                                                       const std::array<glm::dvec2, 4>& pred,
                                                       double search, TagDetection& t) const {
    // Cell size across each edge (the tag's extent along the edge normal over the cells) and the
    // outward normals.
    glm::dvec2 centroid(0.0);
    for (const auto& p : pred) centroid += 0.25 * p;
    std::array<double, 4> cellAcross{};
    std::array<glm::dvec2, 4> normals{};
    for (int k = 0; k < 4; ++k) {
        const glm::dvec2 a = pred[size_t(k)], b = pred[size_t((k + 1) % 4)];
        const glm::dvec2 dir = glm::normalize(b - a);
        glm::dvec2 nrm(-dir.y, dir.x);
        if (glm::dot(nrm, 0.5 * (a + b) - centroid) < 0) nrm = -nrm;  // outward
        const glm::dvec2 opp = 0.5 * (pred[size_t((k + 2) % 4)] + pred[size_t((k + 3) % 4)]);
        cellAcross[size_t(k)] = std::abs(glm::dot(nrm, 0.5 * (a + b) - opp)) / widthAtBorder_;
        normals[size_t(k)] = nrm;
    }
    thread_local std::vector<glm::dvec2> pts;
    thread_local std::vector<double> profile;
    // 1. Coarse edges.
    std::array<ImageLine, 4> lines;
    bool edgesOk = true;
    for (int k = 0; k < 4 && edgesOk; ++k) {
        const glm::dvec2 a = pred[size_t(k)], b = pred[size_t((k + 1) % 4)];
        const glm::dvec2 nrm = normals[size_t(k)];
        const double range =
            std::max(1.5, std::min(search, options_.searchMaxCells * cellAcross[size_t(k)]));
        const double step = 0.5;
        const int nProfile = int(2 * range / step) + 3;  // one extra sample at each end
        const double len = glm::length(b - a);
        const int nSamples = std::clamp(int(len / 3), 6, 16);
        profile.resize(size_t(nProfile));
        pts.clear();
        for (int s = 0; s < nSamples; ++s) {
            const double f = 0.2 + 0.6 * (s + 0.5) / nSamples;
            const glm::dvec2 base = a + f * (b - a);
            bool ok = true;
            for (int i = 0; i < nProfile && ok; ++i) {
                const glm::dvec2 p = base + nrm * (-range - step + i * step);
                ok = sampleLevel(grey, p.x, p.y, profile[size_t(i)]);
            }
            if (!ok) continue;
            // Outward derivative (bright outside the black border is positive); the
            // strongest steps, and of those within half of the strongest, the one closest
            // to the prediction (a data-bit edge of the same polarity lies >= 2 cells in).
            double strongest = 0;
            for (int i = 1; i + 1 < nProfile; ++i)
                strongest = std::max(strongest, profile[size_t(i + 1)] - profile[size_t(i - 1)]);
            if (strongest < 2 * options_.minContrastLevels * step) continue;
            double bestT = 1e9;
            for (int i = 1; i + 1 < nProfile; ++i) {
                const double d0 = profile[size_t(i + 1)] - profile[size_t(i - 1)];
                if (d0 < 0.5 * strongest) continue;
                const double dl = i >= 2 ? profile[size_t(i)] - profile[size_t(i - 2)] : -1e9;
                const double dr =
                    i + 2 < nProfile ? profile[size_t(i + 2)] - profile[size_t(i)] : -1e9;
                if (d0 < dl || d0 < dr) continue;  // not a local maximum
                // Sub-sample peak of the derivative (parabola through three samples).
                double off = 0;
                if (dl > -1e8 && dr > -1e8) {
                    const double den = dl - 2 * d0 + dr;
                    if (den < 0) off = std::clamp(0.5 * (dl - dr) / den, -0.5, 0.5);
                }
                const double t = -range - step + (i + off) * step;
                if (std::abs(t) < std::abs(bestT)) bestT = t;
            }
            if (bestT > 1e8) continue;
            pts.push_back(base + nrm * bestT);
        }
        // Most of the edge must have been found, on a line (robust: refit without points
        // over 0.75 px off).
        if (pts.size() < 4 || 5 * pts.size() < 3 * size_t(nSamples)) {
            edgesOk = false;
            break;
        }
        double rms = 0;
        ImageLine l = fitLine(pts, rms);
        if (rms > 0.5) {
            const glm::dvec2 n(-l.dir.y, l.dir.x);
            std::vector<glm::dvec2> kept;
            for (const auto& p : pts)
                if (std::abs(glm::dot(p - l.point, n)) < 0.75) kept.push_back(p);
            if (kept.size() < 4 || 5 * kept.size() < 3 * size_t(nSamples)) {
                edgesOk = false;
                break;
            }
            l = fitLine(kept, rms);
            if (rms > 0.5) {
                edgesOk = false;
                break;
            }
        }
        lines[size_t(k)] = l;
    }
    if (!edgesOk) return Outcome::EdgeFailed;
    t = TagDetection();
    t.id = m.id;
    for (int k = 0; k < 4 && edgesOk; ++k) {
        // Corner k joins edge k-1 (corner k-1 -> k) and edge k (corner k -> k+1).
        edgesOk = intersect(lines[size_t((k + 3) % 4)], lines[size_t(k)], t.corners[size_t(k)]);
        // The corner may not leave the searched band.
        edgesOk = edgesOk && glm::length(t.corners[size_t(k)] - pred[size_t(k)]) <
                                 2.0 * std::max(1.5, search) + 1.0;
    }
    if (!edgesOk) return Outcome::EdgeFailed;
    // 2. Sub-pixel corners, as after libapriltag.
    if (!Detector::refineCorners(grey, widthAtBorder_, t.corners)) return Outcome::RefineFailed;
    // 3. The tag must be the one the board has there.
    int inner = 0, outer = 0;
    double contrast = 0;
    if (!verify(grey, m.id, t.corners, &inner, &outer, &contrast)) return Outcome::DecodeFailed;
    t.refined = true;
    t.hamming = inner + outer;
    t.decisionMargin = float(contrast);
    t.centre = SquareToQuad({t.corners[3], t.corners[2], t.corners[1], t.corners[0]})(0.5, 0.5);
    return Outcome::Verified;
}

std::vector<TagDetection> PredictedTagFinder::find(const cv::Mat& grey,
                                                   const Pose& T_world_camera_predicted,
                                                   const Pose& T_world_camera_previous,
                                                   PredictedTagStats* statsOut) const {
    return findImpl(grey, T_world_camera_predicted, &T_world_camera_previous, 0.0, nullptr,
                    statsOut);
}

std::vector<TagDetection> PredictedTagFinder::find(const cv::Mat& grey,
                                                   const Pose& T_world_camera_estimated,
                                                   double searchPx,
                                                   const std::vector<TagDetection>& known,
                                                   PredictedTagStats* statsOut) const {
    return findImpl(grey, T_world_camera_estimated, nullptr, searchPx, &known, statsOut);
}

std::vector<PredictedTagFinder::Candidate> PredictedTagFinder::predictCandidates(
    const cv::Mat& grey, const Pose& T_world_camera_predicted, const Pose* T_world_camera_previous,
    double searchPx) const {
    const Pose T_cw = T_world_camera_predicted.inverse();
    // Without a previous pose the corners "moved" by nothing and the radius is searchPx.
    const Pose T_cw_prev =
        (T_world_camera_previous ? *T_world_camera_previous : T_world_camera_predicted).inverse();
    const glm::dvec3 camCentre = T_world_camera_predicted.translation;
    // Centres of the quiet-zone ring's cells lie this many cells outside the corners (+ some for
    // the diagonal and bilinear sampling): they and the edge search must stay inside the image.
    const double ringCells = 0.5 * (totalWidth_ - widthAtBorder_) - 0.25;
    std::vector<Candidate> candidates;
    for (const TagModel& m : tags_) {
        // Facing the camera: the tag's +Z points away from a viewer who reads it.
        if (!(glm::dot(m.normal, m.centre - camCentre) > 0)) continue;
        std::array<glm::dvec2, 4> pred{}, prev{};
        bool inView = true;
        for (int k = 0; k < 4 && inView; ++k) {
            const glm::dvec3 Xc = T_cw * m.world[size_t(k)];
            const glm::dvec3 Xp = T_cw_prev * m.world[size_t(k)];
            if (!(Xc.z > 1e-3) || !(Xp.z > 1e-3)) {
                inView = false;
                break;
            }
            const auto p = camera_.project(Xc);
            const auto q = camera_.project(Xp);
            inView = p && q;
            if (inView) {
                pred[size_t(k)] = *p;
                prev[size_t(k)] = *q;
            }
        }
        if (!inView) continue;
        double minSide = 1e9, maxSide = 0, motion = 0;
        glm::dvec2 centroid(0.0);
        for (int k = 0; k < 4; ++k) {
            const double side = glm::length(pred[size_t(k)] - pred[size_t((k + 1) % 4)]);
            minSide = std::min(minSide, side);
            maxSide = std::max(maxSide, side);
            motion = std::max(motion, glm::length(pred[size_t(k)] - prev[size_t(k)]));
            centroid += 0.25 * pred[size_t(k)];
        }
        if (minSide < options_.minSidePx) continue;
        // Cell size across each edge (the tag's extent along the edge normal over the cells).
        double minCell = 1e9;
        for (int k = 0; k < 4; ++k) {
            const glm::dvec2 a = pred[size_t(k)], b = pred[size_t((k + 1) % 4)];
            const glm::dvec2 dir = glm::normalize(b - a);
            const glm::dvec2 nrm(-dir.y, dir.x);
            const glm::dvec2 opp = 0.5 * (pred[size_t((k + 2) % 4)] + pred[size_t((k + 3) % 4)]);
            minCell =
                std::min(minCell, std::abs(glm::dot(nrm, 0.5 * (a + b) - opp)) / widthAtBorder_);
        }
        if (minCell < options_.minCellPx) continue;
        // The quiet-zone ring and the search must lie inside the image.
        const double search = T_world_camera_previous
                                  ? options_.searchBasePx + options_.searchMotionFactor * motion
                                  : searchPx;
        const double margin = std::max(ringCells * maxSide / widthAtBorder_, search + 0.5) + 2.0;
        bool inside = true;
        for (const auto& p : pred)
            inside = inside && p.x >= margin && p.y >= margin && p.x <= grey.cols - 1 - margin &&
                     p.y <= grey.rows - 1 - margin;
        if (!inside) continue;
        candidates.push_back({&m, pred, search, minSide});
    }
    return candidates;
}

std::vector<TagDetection> PredictedTagFinder::findImpl(
    const cv::Mat& grey, const Pose& T_world_camera_predicted, const Pose* T_world_camera_previous,
    double searchPx, const std::vector<TagDetection>* known, PredictedTagStats* statsOut) const {
    std::vector<TagDetection> out;
    PredictedTagStats stats;
    if (grey.empty() || grey.type() != CV_8UC1) {
        if (statsOut) *statsOut = stats;
        return out;
    }
    std::vector<Candidate> candidates =
        predictCandidates(grey, T_world_camera_predicted, T_world_camera_previous, searchPx);
    stats.predicted = int(candidates.size());

    // Largest tags first (widest search, most reliable); the offsets between predicted and found
    // corners of the tags verified so far correct the predictions of the next ones (a 2D
    // translation from the first tag, an affine map from three on): the prediction error is
    // mostly a shift and rotation of the whole image, which may exceed a small tag's search
    // radius (a cell) though not a large one's. Tags that fail are tried once more with the
    // final correction. Each tag is still verified on its own.
    std::sort(candidates.begin(), candidates.end(),
              [](const Candidate& x, const Candidate& y) { return x.minSide > y.minSide; });
    std::vector<glm::dvec2> from, to;
    ImageCorrection correction;
    std::vector<const Candidate*> retry;
    auto attempt = [&](const Candidate& c, bool firstTry) {
        std::array<glm::dvec2, 4> p = c.pred;
        for (auto& q : p) q = correction(q);
        TagDetection t;
        // Once the affine correction holds (three tags), the corrected prediction is within a
        // fraction of a pixel: a short search suffices on the first try (the retry searches
        // the full radius).
        const double search = firstTry && correction.affine()
                                  ? std::min(c.search, options_.searchCorrectedPx)
                                  : c.search;
        const Outcome o = follow(grey, *c.model, p, search, t);
        if (o == Outcome::Verified) {
            for (int k = 0; k < 4; ++k) {
                from.push_back(c.pred[size_t(k)]);
                to.push_back(t.corners[size_t(k)]);
            }
            correction.fit(from, to);
            out.push_back(t);
            ++stats.verified;
        }
        return o;
    };
    // Tags found already (libapriltag on the decimated image) are taken as they are and only
    // correct the predictions of the others.
    std::vector<bool> isKnown(candidates.size(), false);
    if (known) {
        for (size_t i = 0; i < candidates.size(); ++i)
            for (const auto& d : *known)
                if (d.id == candidates[i].model->id) {
                    isKnown[i] = true;
                    for (int k = 0; k < 4; ++k) {
                        from.push_back(candidates[i].pred[size_t(k)]);
                        to.push_back(d.corners[size_t(k)]);
                    }
                    out.push_back(d);
                    ++stats.verified;
                    break;
                }
        correction.fit(from, to);
    }
    std::vector<Outcome> firstOutcome;
    for (size_t i = 0; i < candidates.size(); ++i) {
        if (isKnown[i]) continue;
        const Candidate& c = candidates[i];
        const Outcome o = attempt(c, true);
        if (o != Outcome::Verified) {
            retry.push_back(&c);
            firstOutcome.push_back(o);
        }
    }
    for (size_t i = 0; i < retry.size(); ++i) {
        // A second try only helps if something was verified (the correction); otherwise the
        // first failure's reason stands.
        const Outcome o = out.empty() ? firstOutcome[i] : attempt(*retry[i], false);
        if (o == Outcome::EdgeFailed) ++stats.edgeFailed;
        if (o == Outcome::RefineFailed) ++stats.refineFailed;
        if (o == Outcome::DecodeFailed) ++stats.decodeFailed;
    }
    if (statsOut) *statsOut = stats;
    return out;
}

}  // namespace mirage::tracking
