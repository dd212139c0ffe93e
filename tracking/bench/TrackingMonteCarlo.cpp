// Monte-Carlo run of the tracker on degraded synthetic views (docs/tracking.md, "Uncertainty and
// the ok state"): prints the per-condition table (states, wrong-but-ok poses, fraction of errors
// inside the reported 2-sigma ellipsoids) and the measured corner noise by blur and tag size.
//   tracking_montecarlo [--views N (2000)] [--one-tag-views M (0)] [--seed S (1)]
//                       [--supersample K (2)] [--previous-rule]
// --one-tag-views: M more views at 0.4-0.7 m in which only one tag is left visible
// (TrialRanges::oneTagOnly, seeds S + 500000 ...), so that the one-tag bin holds enough poses
// to judge.
// --previous-rule: the covariance from the residuals alone (their robust scale) and no bound on
// it for ok (about the rule before the uncertainty bounds; the tag-consistency rule and the
// blur measurement stay), for comparison.
// Single-threaded; about 25 views per second on one core at 640x480.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "testscenes/TrackingViews.h"
#include "tracking/SyntheticTrials.h"

int main(int argc, char** argv) {
    using namespace mirage::tracking;
    int views = 2000, oneTagViews = 0, supersample = 2;
    unsigned long long seed = 1;
    TrackerOptions options;
    int i = 1;
    for (; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--previous-rule")) {
            options.pose.cornerNoisePriorWeight = 0;
            options.pose.tagScaleNoise = options.pose.tagShiftNoise = 0;
            options.pose.commonScaleNoise = 0;
            options.pose.tagCentreNoise = 1;
            options.pose.okMaxSigmaRotDeg = 1e9;
            options.pose.okMaxSigmaPosFraction = 1e9;
            continue;
        }
        if (i + 1 >= argc) break;
        if (!std::strcmp(argv[i], "--views"))
            views = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--one-tag-views"))
            oneTagViews = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--seed"))
            seed = std::strtoull(argv[i + 1], nullptr, 10);
        else if (!std::strcmp(argv[i], "--supersample"))
            supersample = std::atoi(argv[i + 1]);
        else {
            std::fprintf(stderr,
                         "unknown option %s (--views N, --one-tag-views M, --seed S, "
                         "--supersample K, --previous-rule)\n",
                         argv[i]);
            return 2;
        }
        ++i;
    }
    if (i < argc || views <= 0 || oneTagViews < 0 || supersample <= 0) {
        std::fprintf(stderr,
                     "usage: %s [--views N] [--one-tag-views M] [--seed S] [--supersample K] "
                     "[--previous-rule]\n",
                     argv[0]);
        return 2;
    }
    const Board board = BoardLayout().makeBoard();
    auto records = runTrials(board, testing::pinholeCamera(), seed, views, TrialRanges{}, options,
                             supersample);
    if (oneTagViews > 0) {
        TrialRanges oneTag;
        oneTag.oneTagOnly = true;
        oneTag.maxDistanceM = 0.7;  // farther a single tag is mostly ambiguous: no pose to check
        const auto more = runTrials(board, testing::pinholeCamera(), seed + 500000, oneTagViews,
                                    oneTag, options, supersample);
        records.insert(records.end(), more.begin(), more.end());
    }
    std::printf(
        "%d views + %d one-tag views, seed %llu, 640x480 f = 600 px, default board (32 mm "
        "tags)\n\n%s\n%s",
        views, oneTagViews, seed, trialTable(binTrials(records)).c_str(),
        cornerNoiseTable(records).c_str());
    std::printf("\n%s", cornerNoiseSplitTable(records, options.pose).c_str());
    {
        // Median squared Mahalanobis distances (chi-square with 3 degrees of freedom: 2.37).
        std::vector<double> mr, mp;
        for (const auto& r : records)
            if (r.outcome.mahalRot2 >= 0 && (r.outcome.state == TrackingState::Ok ||
                                             r.outcome.state == TrackingState::Uncertain)) {
                mr.push_back(r.outcome.mahalRot2);
                mp.push_back(r.outcome.mahalPos2);
            }
        if (!mr.empty()) {
            std::sort(mr.begin(), mr.end());
            std::sort(mp.begin(), mp.end());
            std::printf(
                "\nmedian squared Mahalanobis distance (3 dof: 2.37 when honest): rotation "
                "%.2f, position %.2f\n",
                mr[mr.size() / 2], mp[mp.size() / 2]);
        }
    }
    if (std::getenv("MIRAGE_MC_OUTSIDE")) {
        std::printf(
            "\nposes outside the 2-sigma ellipsoid (seed: state, tags, smallest px, blur, "
            "widths, gain, q, mahal rot / pos):\n");
        for (const auto& r : records) {
            const TrialOutcome& o = r.outcome;
            if (o.mahalRot2 < 0 ||
                (o.mahalRot2 <= kChi2ThreeDof2Sigma && o.mahalPos2 <= kChi2ThreeDof2Sigma))
                continue;
            if (o.state != TrackingState::Ok && o.state != TrackingState::Uncertain) continue;
            std::string w;
            for (const auto& t : r.tags) w += std::to_string(t.edgeWidthPx).substr(0, 4) + " ";
            std::printf("  %llu: %s, %d, %.1f, %.1f, [%s], %.2f, %d, %.1f / %.1f\n",
                        (unsigned long long)r.seed, trackingStateName(o.state), o.tags, o.minSidePx,
                        r.degradation.blurPx, w.substr(0, 40).c_str(), r.degradation.gain,
                        r.degradation.jpegQuality, o.mahalRot2, o.mahalPos2);
        }
    }
    std::printf(
        "\nwrong-but-ok views (seed: tags, smallest tag px, blur px, JPEG q, gain, "
        "error deg / %%, 1 sigma deg / %%):\n");
    for (const auto& r : records) {
        const TrialOutcome& o = r.outcome;
        if (o.state != TrackingState::Ok || !o.wrong) continue;
        std::printf("  %llu: %d, %.1f, %.1f, %d, %.2f, %.2f / %.2f, %.2f / %.2f\n",
                    (unsigned long long)r.seed, o.tags, o.minSidePx, r.degradation.blurPx,
                    r.degradation.jpegQuality, r.degradation.gain, o.rotErrDeg, 100 * o.transErrRel,
                    o.sigmaRotDeg, 100 * o.sigmaPosRel);
    }
    return 0;
}
