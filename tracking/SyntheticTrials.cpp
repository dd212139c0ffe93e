#include "tracking/SyntheticTrials.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/image/ImageIO.h"
#include "core/math/Pose.h"
#include "tracking/SyntheticBoardView.h"

namespace mirage::tracking {
namespace {

// Kernel of a motion blur of `length` pixels along `angle`: the segment sampled densely and
// splatted bilinearly, normalised to sum 1.
cv::Mat lineKernel(double length, double angle) {
    const int half = int(std::ceil(length / 2)) + 1;
    cv::Mat k = cv::Mat::zeros(2 * half + 1, 2 * half + 1, CV_32F);
    const int samples = std::max(8, int(length * 16));
    const double dx = std::cos(angle), dy = std::sin(angle);
    for (int i = 0; i < samples; ++i) {
        const double s = (i + 0.5) / samples - 0.5;
        const double x = half + s * length * dx, y = half + s * length * dy;
        const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
        const float fx = float(x - x0), fy = float(y - y0);
        k.at<float>(y0, x0) += (1 - fx) * (1 - fy);
        k.at<float>(y0, x0 + 1) += fx * (1 - fy);
        k.at<float>(y0 + 1, x0) += (1 - fx) * fy;
        k.at<float>(y0 + 1, x0 + 1) += fx * fy;
    }
    return k / cv::sum(k)[0];
}

double mahalanobis2(const std::array<double, 36>& c, int offset, const glm::dvec3& e) {
    cv::Matx33d S;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) S(a, b) = c[size_t((offset + a) * 6 + offset + b)];
    cv::Matx33d inv;
    if (cv::invert(S, inv, cv::DECOMP_CHOLESKY) == 0) return -1;
    const cv::Vec3d v(e.x, e.y, e.z);
    return v.dot(inv * v);
}

}  // namespace

cv::Mat degradeView(const cv::Mat& grey, const Degradation& d) {
    CV_Assert(grey.type() == CV_8UC1);
    // To linear light (the scene's radiance): blur and exposure act there, as in a camera.
    std::array<float, 256> lut{};
    for (int i = 0; i < 256; ++i) lut[size_t(i)] = srgbToLinear(float(i) / 255.0f);
    cv::Mat lin(grey.size(), CV_32F);
    for (int y = 0; y < grey.rows; ++y) {
        const uint8_t* s = grey.ptr<uint8_t>(y);
        float* o = lin.ptr<float>(y);
        for (int x = 0; x < grey.cols; ++x) o[x] = lut[s[x]];
    }
    if (d.occluder) {
        const float level = srgbToLinear(float(d.occluderLevel) / 255.0f);
        cv::ellipse(lin, d.occluderShape, cv::Scalar(level), cv::FILLED, cv::LINE_AA);
    }
    if (d.blurPx >= 0.5)
        cv::filter2D(lin, lin, -1, lineKernel(d.blurPx, d.blurAngleRad), {-1, -1}, 0,
                     cv::BORDER_REPLICATE);
    cv::RNG rng(d.seed);
    cv::Mat out(grey.size(), CV_8UC1);
    for (int y = 0; y < grey.rows; ++y) {
        const float* s = lin.ptr<float>(y);
        uint8_t* o = out.ptr<uint8_t>(y);
        for (int x = 0; x < grey.cols; ++x) {
            const float v = std::min(1.0f, float(d.gain) * s[x]);
            double enc = 255.0 * linearToSrgb(v);
            if (d.noiseLevels > 0) enc += rng.gaussian(d.noiseLevels);
            o[x] = uint8_t(std::clamp(std::lround(enc), 0L, 255L));
        }
    }
    if (d.jpegQuality > 0) {
        std::vector<uchar> buf;
        cv::imencode(".jpg", out, buf, {cv::IMWRITE_JPEG_QUALITY, d.jpegQuality});
        out = cv::imdecode(buf, cv::IMREAD_GRAYSCALE);
    }
    return out;
}

glm::dvec3 boardCentre(const Board& board) {
    glm::dvec3 c(0.0);
    for (const auto& t : board.tags) c += t.T_world_tag.translation;
    return board.tags.empty() ? c : c / double(board.tags.size());
}

TrialView makeTrialView(const Board& board, const BoardRaster& texture,
                        const CameraIntrinsics& camera, uint64_t seed, const TrialRanges& r,
                        int supersample) {
    cv::RNG rng(seed * 2654435761ull + 12345);
    const glm::dvec3 centre = boardCentre(board);
    // Board normal and in-plane axes from the first tag (+Z of a tag points into the board).
    const glm::dmat3 Rt = board.tags.front().T_world_tag.rotationMatrix();
    const glm::dvec3 normal = -Rt[2], ax = Rt[0], ay = Rt[1];
    const double dist = rng.uniform(r.minDistanceM, r.maxDistanceM);
    // Tilt uniform in solid angle up to maxTiltDeg.
    const double cosMax = std::cos(glm::radians(r.maxTiltDeg));
    const double tilt = std::acos(rng.uniform(cosMax, 1.0));
    const double az = rng.uniform(0.0, 2 * M_PI);
    const glm::dvec3 dir =
        std::cos(tilt) * normal + std::sin(tilt) * (std::cos(az) * ax + std::sin(az) * ay);
    // Aim point off the board centre, within the image footprint at that distance.
    const double halfW = dist * 0.5 * camera.width / camera.fx;
    const double halfH = dist * 0.5 * camera.height / camera.fy;
    glm::dvec3 target = centre + rng.uniform(-1.0, 1.0) * r.maxAimOffset * halfW * ax +
                        rng.uniform(-1.0, 1.0) * r.maxAimOffset * halfH * ay;
    const BoardTag* onlyTag = nullptr;
    if (r.oneTagOnly) {
        onlyTag = &board.tags[size_t(rng.uniform(0, int(board.tags.size())))];
        const double halfTag = onlyTag->size * 0.5 * (12.0 / 8.0);
        target = onlyTag->T_world_tag.translation +
                 rng.uniform(-1.0, 1.0) * r.maxAimOffset * std::min(halfW, 4 * halfTag) * ax +
                 rng.uniform(-1.0, 1.0) * r.maxAimOffset * std::min(halfH, 4 * halfTag) * ay;
    }
    const glm::dvec3 eye = target + dist * dir;
    // Up direction: the board's in-plane axis, turned by a random roll.
    const double roll = rng.uniform(-M_PI, M_PI);
    const glm::dvec3 forward = glm::normalize(target - eye);
    glm::dvec3 up = std::cos(roll) * ax + std::sin(roll) * ay;
    up = glm::normalize(up - glm::dot(up, forward) * forward);
    const glm::dvec3 right = glm::normalize(glm::cross(forward, up));
    const glm::dvec3 down = glm::cross(forward, right);

    TrialView v;
    v.truth = Pose::fromRotationTranslation(glm::dmat3(right, down, forward), eye);
    v.distanceM = glm::length(eye - centre);
    Degradation& d = v.degradation;
    d.seed = seed;
    if (rng.uniform(0.0, 1.0) < 0.5) {
        d.blurPx = rng.uniform(0.0, r.maxBlurPx);
        d.blurAngleRad = rng.uniform(0.0, M_PI);
    }
    if (rng.uniform(0.0, 1.0) < 0.75)
        d.jpegQuality = rng.uniform(r.minJpegQuality, r.maxJpegQuality + 1);
    d.gain = std::exp(rng.uniform(std::log(r.minGain), std::log(r.maxGain)));
    d.noiseLevels = rng.uniform(0.0, r.maxNoiseLevels);
    if (rng.uniform(0.0, 1.0) < r.occluderProbability) {
        d.occluder = true;
        const float w = float(camera.width), h = float(camera.height);
        d.occluderShape =
            cv::RotatedRect({rng.uniform(0.0f, w), rng.uniform(0.0f, h)},
                            {rng.uniform(0.1f * w, 0.5f * w), rng.uniform(0.05f * h, 0.3f * h)},
                            rng.uniform(0.0f, 180.0f));
        d.occluderLevel = uint8_t(rng.uniform(20, 200));
    }
    SyntheticViewOptions so;
    so.supersample = supersample;
    cv::Mat view = renderSyntheticBoardView(board, texture, camera, v.truth, so);
    if (onlyTag) {
        // Everything but the tag and its quiet zone (one cell beyond the detection corners, 10
        // of the tag's 8 border-to-border cells) plus a margin of one more cell: grey.
        v.onlyTagId = onlyTag->id;
        const Pose T_cw = v.truth.inverse();
        std::vector<cv::Point> poly;
        for (const auto& c : BoardTag::cornersInTag(onlyTag->size * 12.0 / 8.0)) {
            const auto px = camera.project(T_cw * (onlyTag->T_world_tag * c));
            if (px) poly.emplace_back(int(std::lround(px->x)), int(std::lround(px->y)));
        }
        cv::Mat mask(view.size(), CV_8U, cv::Scalar(0));
        if (poly.size() == 4) cv::fillConvexPoly(mask, poly, cv::Scalar(255));
        view.setTo(cv::Scalar(d.occluderLevel), mask == 0);
    }
    v.image = degradeView(view, d);
    return v;
}

TrialOutcome scoreEstimate(const PoseEstimate& e, const Pose& truth, const Board& board,
                           const CameraIntrinsics& camera) {
    TrialOutcome o;
    o.state = e.state;
    o.tags = int(e.tagsUsed.size());
    o.distanceM = glm::length(truth.translation - boardCentre(board));
    const Pose T_cw = truth.inverse();
    o.minSidePx = 1e9;
    for (int id : e.tagsUsed) {
        const BoardTag* t = board.find(id);
        if (!t) continue;
        std::array<glm::dvec2, 4> px{};
        const auto c = t->cornersInWorld();
        for (int k = 0; k < 4; ++k)
            px[size_t(k)] = camera.project(T_cw * c[size_t(k)]).value_or(glm::dvec2(0));
        for (int k = 0; k < 4; ++k)
            o.minSidePx =
                std::min(o.minSidePx, glm::length(px[size_t(k)] - px[size_t((k + 1) % 4)]));
    }
    if (o.minSidePx > 1e8) o.minSidePx = 0;
    if (!e.pose) return o;
    const glm::dvec3 eRot = rotationVector(e.pose->rotation * glm::inverse(truth.rotation));
    const glm::dvec3 ePos = e.pose->translation - truth.translation;
    o.rotErrDeg = glm::degrees(glm::length(eRot));
    o.transErrRel = glm::length(ePos) / o.distanceM;
    o.wrong = o.rotErrDeg > 2.0 || o.transErrRel > 0.02;
    const auto& c = e.covariance;
    if (c[0] > 0 && c[21] > 0) {
        o.mahalRot2 = mahalanobis2(c, 0, eRot);
        o.mahalPos2 = mahalanobis2(c, 3, ePos);
        o.sigmaRotDeg = glm::degrees(std::sqrt(c[0] + c[7] + c[14]));
        o.sigmaPosRel = std::sqrt(c[21] + c[28] + c[35]) / o.distanceM;
    }
    return o;
}

void TrialBin::add(const TrialOutcome& o) {
    ++views;
    switch (o.state) {
        case TrackingState::Ok:
            ++ok;
            break;
        case TrackingState::Uncertain:
            ++uncertain;
            break;
        case TrackingState::Ambiguous:
            ++ambiguous;
            break;
        case TrackingState::Lost:
            ++lost;
            break;
        default:
            ++noPose;
            break;
    }
    if (o.state == TrackingState::Ok && o.wrong) ++wrongOk;
    const bool reported = o.state == TrackingState::Ok || o.state == TrackingState::Uncertain;
    if (reported && o.mahalRot2 >= 0 && o.mahalPos2 >= 0) {
        ++withCov;
        const bool r = o.mahalRot2 <= kChi2ThreeDof2Sigma, p = o.mahalPos2 <= kChi2ThreeDof2Sigma;
        rotIn2Sigma += r;
        posIn2Sigma += p;
        if (o.state == TrackingState::Ok) {
            okRotIn2Sigma += r;
            okPosIn2Sigma += p;
        }
    }
}

std::string trialTable(const std::vector<TrialBin>& bins) {
    std::string s =
        "| condition | views | ok | uncertain | ambiguous | lost | no pose | wrong-but-ok | "
        "poses with covariance | rotation within 2 sigma | position within 2 sigma |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|\n";
    char b[512];
    for (const auto& x : bins) {
        auto pct = [](int a, int n) { return n > 0 ? 100.0 * a / n : 0.0; };
        std::snprintf(
            b, sizeof b,
            "| %s | %d | %d (%.0f %%) | %d | %d | %d | %d | %d | %d | %.1f %% | %.1f %% |\n",
            x.name.c_str(), x.views, x.ok, pct(x.ok, x.views), x.uncertain, x.ambiguous, x.lost,
            x.noPose, x.wrongOk, x.withCov, pct(x.rotIn2Sigma, x.withCov),
            pct(x.posIn2Sigma, x.withCov));
        s += b;
    }
    return s;
}

}  // namespace mirage::tracking

namespace mirage::tracking {

std::vector<TrialRecord> runTrials(const Board& board, const CameraIntrinsics& camera,
                                   uint64_t firstSeed, int count, const TrialRanges& ranges,
                                   const TrackerOptions& options, int supersample) {
    const BoardRaster texture = renderBoard(board, 8000, false);
    Tracker tracker(board, camera, options);
    std::vector<TrialRecord> out;
    for (int i = 0; i < count; ++i) {
        const TrialView v =
            makeTrialView(board, texture, camera, firstSeed + uint64_t(i), ranges, supersample);
        const TrackedFrame f = tracker.process(v.image, 10.0 * i);
        TrialRecord r;
        r.seed = firstSeed + uint64_t(i);
        r.distanceM = v.distanceM;
        r.degradation = v.degradation;
        r.outcome = scoreEstimate(f.estimate, v.truth, board, camera);
        r.truth = v.truth;
        r.detections = f.detections;
        const Pose T_cw = v.truth.inverse();
        for (const auto& d : f.detections) {
            const BoardTag* t = board.find(d.id);
            if (!t) continue;
            const auto c = t->cornersInWorld();
            std::array<glm::dvec2, 4> px{};
            bool in = true;
            for (int k = 0; k < 4 && in; ++k) {
                const auto p = camera.project(T_cw * c[size_t(k)]);
                in = p.has_value();
                if (p) px[size_t(k)] = *p;
            }
            if (!in) continue;
            TrialRecord::TagCorners tc;
            tc.sidePx = 1e9;
            double s2 = 0;
            for (int k = 0; k < 4; ++k) {
                tc.sidePx =
                    std::min(tc.sidePx, glm::length(px[size_t(k)] - px[size_t((k + 1) % 4)]));
                const glm::dvec2 e = d.corners[size_t(k)] - px[size_t(k)];
                s2 += glm::dot(e, e);
            }
            tc.rmsErrPx = std::sqrt(s2 / 4);
            glm::dvec2 centre(0.0), mean(0.0);
            for (int k = 0; k < 4; ++k) {
                centre += 0.25 * px[size_t(k)];
                mean += 0.25 * (d.corners[size_t(k)] - px[size_t(k)]);
            }
            double scale = 0;
            std::array<glm::dvec2, 4> radial{};
            for (int k = 0; k < 4; ++k) {
                radial[size_t(k)] = glm::normalize(px[size_t(k)] - centre);
                scale += 0.25 * glm::dot(d.corners[size_t(k)] - px[size_t(k)], radial[size_t(k)]);
            }
            double left = 0;
            for (int k = 0; k < 4; ++k) {
                const glm::dvec2 e =
                    d.corners[size_t(k)] - px[size_t(k)] - mean - scale * radial[size_t(k)];
                left += glm::dot(e, e);
            }
            tc.scalePx = scale;
            tc.shiftPx = mean;
            tc.independentPx = std::sqrt(left / 5.0);  // 8 values, 3 taken by shift and scale
            tc.edgeWidthPx = tagEdgeWidthPx(v.image, d.corners);
            r.tags.push_back(tc);
        }
        out.push_back(std::move(r));
    }
    return out;
}

std::vector<TrialRecord> rescoreTrials(const std::vector<TrialRecord>& records, const Board& board,
                                       const CameraIntrinsics& camera,
                                       const PoseEstimatorOptions& options) {
    const PoseEstimator estimator(board, camera, options);
    std::vector<TrialRecord> out = records;
    for (auto& r : out) {
        // A frame without a board tag may have been judged too blurred by the tracker; the
        // estimator alone cannot tell, and neither state has a pose.
        const TrackingState before = r.outcome.state;
        r.outcome = scoreEstimate(estimator.estimate(r.detections), r.truth, board, camera);
        if (before == TrackingState::TooBlurred && r.outcome.state == TrackingState::NoTags)
            r.outcome.state = before;
    }
    return out;
}

std::vector<TrialBin> binTrials(const std::vector<TrialRecord>& records) {
    struct Rule {
        std::string name;
        std::function<bool(const TrialRecord&)> in;
    };
    const std::vector<Rule> rules = {
        {"all views", [](const TrialRecord&) { return true; }},
        {"blur < 1 px", [](const TrialRecord& r) { return r.degradation.blurPx < 1; }},
        {"blur 1-4 px",
         [](const TrialRecord& r) {
             return r.degradation.blurPx >= 1 && r.degradation.blurPx < 4;
         }},
        {"blur 4-7 px", [](const TrialRecord& r) { return r.degradation.blurPx >= 4; }},
        {"no JPEG", [](const TrialRecord& r) { return r.degradation.jpegQuality == 0; }},
        {"JPEG q60-77",
         [](const TrialRecord& r) {
             return r.degradation.jpegQuality > 0 && r.degradation.jpegQuality < 78;
         }},
        {"JPEG q78-95", [](const TrialRecord& r) { return r.degradation.jpegQuality >= 78; }},
        {"gain < 0.8 or > 1.25",
         [](const TrialRecord& r) {
             return r.degradation.gain < 0.8 || r.degradation.gain > 1.25;
         }},
        {"occluder", [](const TrialRecord& r) { return r.degradation.occluder; }},
        {"distance 0.4-0.67 m", [](const TrialRecord& r) { return r.distanceM < 0.67; }},
        {"distance 0.67-0.93 m",
         [](const TrialRecord& r) { return r.distanceM >= 0.67 && r.distanceM < 0.93; }},
        {"distance 0.93-1.2+ m", [](const TrialRecord& r) { return r.distanceM >= 0.93; }},
        {"1 tag used", [](const TrialRecord& r) { return r.outcome.tags == 1; }},
        {"2-3 tags used",
         [](const TrialRecord& r) { return r.outcome.tags >= 2 && r.outcome.tags <= 3; }},
        {"4-11 tags used",
         [](const TrialRecord& r) { return r.outcome.tags >= 4 && r.outcome.tags <= 11; }},
        {"12+ tags used", [](const TrialRecord& r) { return r.outcome.tags >= 12; }},
        {"smallest used tag < 20 px",
         [](const TrialRecord& r) { return r.outcome.tags > 0 && r.outcome.minSidePx < 20; }},
        {"smallest used tag 20-30 px",
         [](const TrialRecord& r) {
             return r.outcome.tags > 0 && r.outcome.minSidePx >= 20 && r.outcome.minSidePx < 30;
         }},
        {"smallest used tag >= 30 px",
         [](const TrialRecord& r) { return r.outcome.tags > 0 && r.outcome.minSidePx >= 30; }},
    };
    std::vector<TrialBin> bins;
    for (const auto& rule : rules) {
        TrialBin b;
        b.name = rule.name;
        for (const auto& r : records)
            if (rule.in(r)) b.add(r.outcome);
        bins.push_back(b);
    }
    return bins;
}

std::string cornerNoiseSplitTable(const std::vector<TrialRecord>& records,
                                  const PoseEstimatorOptions& m) {
    const double blurEdges[] = {0, 1, 2.5, 4, 5.5, 7.01};
    std::string s =
        "| blur px | tags | sigma0 px (model, RMS) | independent px | tag scale px | tag shift px "
        "(per axis) | frame scale px |\n|---|---|---|---|---|---|---|\n";
    char b[256];
    for (int i = 0; i < 5; ++i) {
        double s0 = 0, ind = 0, sc = 0, sh = 0, fr = 0;
        int n = 0, frames = 0;
        for (const auto& r : records) {
            if (r.degradation.blurPx < blurEdges[i] || r.degradation.blurPx >= blurEdges[i + 1])
                continue;
            double frameScale = 0;
            int nt = 0;
            for (const auto& t : r.tags) {
                const double blur = std::max(0.0, t.edgeWidthPx - 2.2);
                const double z = m.cornerNoisePx + m.cornerNoiseSidePx / std::max(1.0, t.sidePx) +
                                 m.cornerNoiseBlur * blur * blur;
                s0 += z * z;
                ind += t.independentPx * t.independentPx;
                sc += t.scalePx * t.scalePx;
                sh += 0.5 * glm::dot(t.shiftPx, t.shiftPx);
                frameScale += t.scalePx;
                ++n;
                ++nt;
            }
            if (nt >= 4) {
                fr += (frameScale / nt) * (frameScale / nt);
                ++frames;
            }
        }
        if (n == 0) continue;
        std::snprintf(
            b, sizeof b, "| %.1f-%.1f | %d | %.3f | %.3f | %.3f | %.3f | %.3f (%d frames) |\n",
            blurEdges[i], std::min(7.0, blurEdges[i + 1]), n, std::sqrt(s0 / n), std::sqrt(ind / n),
            std::sqrt(sc / n), std::sqrt(sh / n), frames ? std::sqrt(fr / frames) : 0.0, frames);
        s += b;
    }
    return s;
}

// The q-quantile (0..1) of sorted values, interpolated linearly between neighbours (so the
// median of two values is their mean and never exceeds the 90th percentile).
static double quantile(const std::vector<double>& sorted, double q) {
    const double at = q * double(sorted.size() - 1);
    const size_t lo = size_t(at);
    const size_t hi = std::min(lo + 1, sorted.size() - 1);
    return sorted[lo] + (at - double(lo)) * (sorted[hi] - sorted[lo]);
}

// One table cell: " median / 90th percentile (count) |" of `values`, or " - |" when empty.
static std::string medianP90Cell(std::vector<double> values) {
    if (values.empty()) return " - |";
    std::sort(values.begin(), values.end());
    char b[64];
    std::snprintf(b, sizeof b, " %.3f / %.3f (%zu) |", quantile(values, 0.5), quantile(values, 0.9),
                  values.size());
    return b;
}

std::string cornerNoiseTable(const std::vector<TrialRecord>& records) {
    const double blurEdges[] = {0, 1, 2.5, 4, 5.5, 7.01};
    const double sideEdges[] = {0, 20, 25, 30, 40, 1e9};
    std::string s =
        "| blur px \\ tag side px | < 20 | 20-25 | 25-30 | 30-40 | >= 40 |\n"
        "|---|---|---|---|---|---|\n";
    char b[128];
    for (int i = 0; i < 5; ++i) {
        std::snprintf(b, sizeof b, "| %.1f-%.1f |", blurEdges[i], std::min(7.0, blurEdges[i + 1]));
        s += b;
        for (int j = 0; j < 5; ++j) {
            std::vector<double> e;
            for (const auto& r : records) {
                const double blur = r.degradation.blurPx;
                if (blur < blurEdges[i] || blur >= blurEdges[i + 1]) continue;
                for (const auto& t : r.tags)
                    if (t.sidePx >= sideEdges[j] && t.sidePx < sideEdges[j + 1])
                        e.push_back(t.rmsErrPx);
            }
            s += medianP90Cell(e);
        }
        s += "\n";
    }
    s += "(median / 90th percentile of the per-tag corner error RMS, pixels; in brackets the "
         "number of tags)\n\n";
    // The same by the measured edge width (what the tracker sees of the blur).
    const double widthEdges[] = {0, 2.5, 3.5, 4.5, 6, 1e9};
    s += "| edge width px (measured) \\ tag side px | < 20 | 20-25 | 25-30 | 30-40 | >= 40 |\n"
         "|---|---|---|---|---|---|\n";
    for (int i = 0; i < 5; ++i) {
        std::snprintf(b, sizeof b, "| %.1f-%.1f |", widthEdges[i],
                      std::min(99.0, widthEdges[i + 1]));
        s += b;
        for (int j = 0; j < 5; ++j) {
            std::vector<double> e;
            for (const auto& r : records)
                for (const auto& t : r.tags)
                    if (t.sidePx >= sideEdges[j] && t.sidePx < sideEdges[j + 1] &&
                        t.edgeWidthPx >= widthEdges[i] && t.edgeWidthPx < widthEdges[i + 1])
                        e.push_back(t.rmsErrPx);
            s += medianP90Cell(e);
        }
        s += "\n";
    }
    // Measured edge width against the true blur.
    s += "\n| blur px (true) | edge width px (measured): median / 10th / 90th percentile "
         "|\n|---|---|\n";
    for (int i = 0; i < 5; ++i) {
        std::vector<double> w;
        for (const auto& r : records)
            if (r.degradation.blurPx >= blurEdges[i] && r.degradation.blurPx < blurEdges[i + 1])
                for (const auto& t : r.tags)
                    if (t.edgeWidthPx > 0) w.push_back(t.edgeWidthPx);
        if (w.empty()) continue;
        std::sort(w.begin(), w.end());
        std::snprintf(b, sizeof b, "| %.1f-%.1f | %.2f / %.2f / %.2f |\n", blurEdges[i],
                      std::min(7.0, blurEdges[i + 1]), quantile(w, 0.5), quantile(w, 0.1),
                      quantile(w, 0.9));
        s += b;
    }
    return s;
}

}  // namespace mirage::tracking
