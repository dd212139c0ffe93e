// fisheye_montecarlo: draws of calibration/FisheyeMonteCarlo.h, one table row per draw, then the
// acceptance checks (docs/calibration.md, "Fish-eye to the rim"):
//  - mirage's mean projection difference from the true lens up to 80 degrees <= 0.25 px in every
//    draw;
//  - never worse than cv::fisheye::calibrate on the same detected corners by more than
//    10 % + 0.1 px;
//  - the true mean difference within 2 stated sigma in >= 90 % of the draws.
// Exit code 0 when all hold, 2 when one fails, 1 on bad arguments.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "calibration/FisheyeMonteCarlo.h"

int main(int argc, char** argv) {
    using namespace mirage::calib;
    int seeds = 20;
    unsigned first = 1;
    FisheyeDrawOptions o;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--seeds" && i + 1 < argc)
            seeds = std::atoi(argv[++i]);
        else if (a == "--first-seed" && i + 1 < argc)
            first = unsigned(std::atoi(argv[++i]));
        else if (a == "--views" && i + 1 < argc)
            o.views = std::atoi(argv[++i]);
        else {
            std::fprintf(stderr,
                         "usage: %s [--seeds N (20)] [--first-seed S (1)] [--views V (20)]\n",
                         argv[0]);
            return 1;
        }
    }
    if (seeds < 1 || o.views < 4) {
        std::fprintf(stderr, "--seeds must be >= 1 and --views >= 4\n");
        return 1;
    }
    std::printf(
        "| seed | lens | field deg | blur px | noise | views det. / fallback / used | dropped "
        "corners | reach deg | mirage mean / max px | OpenCV mean px | stated 1-sigma px | "
        "mean / sigma |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    int within2 = 0, draws = 0, over025 = 0, worseThanCv = 0, cvFailed = 0;
    double worstMean = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (unsigned s = first; s < first + unsigned(seeds); ++s) {
        const FisheyeDraw d = runFisheyeDraw(s, o);
        ++draws;
        if (!d.error.empty()) {
            std::printf("| %u | %s | %.0f | - | - | %d / %d / - | - | - | FAILED: %s | | | |\n", s,
                        fisheyeLensName(d.lens), d.fovDeg, d.viewsDetected, d.fallbackViews,
                        d.error.c_str());
            ++over025;
            continue;
        }
        const double ratio = d.mirageMeanPx / d.statedStdPx;
        if (ratio <= 2.0) ++within2;
        if (!(d.mirageMeanPx <= 0.25)) ++over025;
        if (std::isnan(d.opencvMeanPx))
            ++cvFailed;
        else if (d.mirageMeanPx > 1.1 * d.opencvMeanPx + 0.1)
            ++worseThanCv;
        worstMean = std::max(worstMean, d.mirageMeanPx);
        std::printf(
            "| %u | %s | %.0f | %.2f | %.1f | %d / %d / %d | %d | %.1f | %.3f / %.3f | %s | %.3f | "
            "%.2f |\n",
            s, fisheyeLensName(d.lens), d.fovDeg, d.blurPx, d.noiseLevels, d.viewsDetected,
            d.fallbackViews, d.viewsUsed, d.droppedCorners, d.reachDeg, d.mirageMeanPx,
            d.mirageMaxPx,
            std::isnan(d.opencvMeanPx) ? "failed"
                                       : std::to_string(d.opencvMeanPx).substr(0, 5).c_str(),
            d.statedStdPx, ratio);
        std::fflush(stdout);
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double share = 100.0 * within2 / draws;
    std::printf("\n%d draws in %.0f s\n", draws, seconds);
    std::printf("mean difference <= 0.25 px in every draw: %s (worst %.3f px, %d over)\n",
                over025 == 0 ? "yes" : "NO", worstMean, over025);
    std::printf(
        "never worse than OpenCV by more than 10 %% + 0.1 px: %s (%d worse; OpenCV failed "
        "in %d draws)\n",
        worseThanCv == 0 ? "yes" : "NO", worseThanCv, cvFailed);
    std::printf("true mean difference within 2 stated sigma: %.0f %% of the draws (>= 90 %%: %s)\n",
                share, share >= 90 ? "yes" : "NO");
    return over025 == 0 && worseThanCv == 0 && share >= 90 ? 0 : 2;
}
