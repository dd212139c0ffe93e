#include "calibration/ResponseFit.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <fmt/format.h>
#include <opencv2/photo.hpp>

#include "core/Error.h"

namespace mirage::calibration {
namespace {

// Codes whose fitted value is trusted: away from the noise floor and from clipping. Outside,
// the curve is continued as the power law fitted inside (Debevec's curve is only weakly
// constrained there: few samples, and saturated pixels carry no measurement).
constexpr int kLowCode = 16, kHighCode = 239;

void checkBracket(const std::vector<BracketImage>& bracket) {
    if (bracket.size() < 3)
        throw Error(
            fmt::format("camera response: {} image(s) in the bracket; take at least 3 "
                        "(better 5-7) of the same still scene at different exposures",
                        bracket.size()));
    std::set<double> times;
    for (const BracketImage& b : bracket) {
        if (b.bgr8.type() != CV_8UC3 || b.bgr8.empty())
            throw Error(fmt::format("camera response: {}: not an 8-bit colour image", b.name));
        if (b.bgr8.size() != bracket.front().bgr8.size())
            throw Error(
                fmt::format("camera response: {} is {}x{}, {} is {}x{}; every picture of "
                            "a bracket has the same size",
                            b.name, b.bgr8.cols, b.bgr8.rows, bracket.front().name,
                            bracket.front().bgr8.cols, bracket.front().bgr8.rows));
        if (!(std::isfinite(b.exposureSeconds) && b.exposureSeconds > 0))
            throw Error(
                fmt::format("camera response: {}: exposure time {} is not a positive "
                            "number",
                            b.name, b.exposureSeconds));
        times.insert(b.exposureSeconds);
    }
    if (times.size() < 3)
        throw Error(
            fmt::format("camera response: only {} distinct exposure time(s); a bracket "
                        "needs at least 3 (e.g. each twice the one before)",
                        times.size()));
}

// Share of the codes kLowCode..kHighCode that some pixel of some image shows (green channel).
double codeCoverage(const std::vector<BracketImage>& bracket) {
    std::vector<bool> seen(256, false);
    for (const BracketImage& b : bracket)
        for (int y = 0; y < b.bgr8.rows; ++y)
            for (int x = 0; x < b.bgr8.cols; ++x) seen[b.bgr8.at<cv::Vec3b>(y, x)[1]] = true;
    int n = 0;
    for (int c = kLowCode; c <= kHighCode; ++c) n += seen[size_t(c)] ? 1 : 0;
    return double(n) / double(kHighCode - kLowCode + 1);
}

// Least-squares exponent G of ln f(c) = a + G ln(c / 255) over the trusted codes.
void fitPowerLaw(const CameraResponse::Curve& f, double& a, double& g) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (int c = kLowCode; c <= kHighCode; ++c) {
        const double x = std::log(double(c) / 255.0), y = std::log(double(f[size_t(c)]));
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
        ++n;
    }
    g = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    a = (sy - g * sx) / n;
}

}  // namespace

ResponseFit fitCameraResponse(const std::vector<BracketImage>& bracket, int samples,
                              float smoothness) {
    checkBracket(bracket);
    const double coverage = codeCoverage(bracket);
    if (coverage < 0.5)
        throw Error(
            fmt::format("camera response: the bracket shows {:.0f} % of the codes {}..{}; "
                        "picture a scene with dark and bright parts (the board under a "
                        "lamp) over a wider range of exposures",
                        100 * coverage, kLowCode, kHighCode));
    std::vector<cv::Mat> images;
    std::vector<float> times;
    for (const BracketImage& b : bracket) {
        images.push_back(b.bgr8);
        times.push_back(float(b.exposureSeconds));
    }
    cv::Mat curve;  // 256 x 1, CV_32FC3 (B, G, R): exposure-relative radiance per code
    cv::createCalibrateDebevec(samples, smoothness, /*random=*/false)
        ->process(images, curve, times);

    std::array<CameraResponse::Curve, 3> inverse{};
    double gammaSum = 0;
    for (int ch = 0; ch < 3; ++ch) {
        CameraResponse::Curve& f = inverse[size_t(ch)];
        float running = 0.0f;
        for (int c = 0; c < 256; ++c) {
            const float v = curve.at<cv::Vec3f>(c, 0)[2 - ch];
            // A response never decreases: noise in the fit is flattened.
            running = std::max(running, std::isfinite(v) && v > 0 ? v : 0.0f);
            f[size_t(c)] = running;
        }
        if (!(f[size_t(kLowCode)] > 0))
            throw Error(
                "camera response: the fit gives no light at the low codes; the bracket "
                "is too dark");
        double a = 0, g = 0;
        fitPowerLaw(f, a, g);
        if (!(std::isfinite(g) && g > 0.3 && g < 6))
            throw Error(
                fmt::format("camera response: the fitted curve (exponent {:.3g}) is not a "
                            "camera's; check the exposure times and that nothing moved",
                            g));
        gammaSum += g;
        // Continue the trusted part with its own local power law towards 0 and 255.
        const double lo = f[size_t(kLowCode)], hi = f[size_t(kHighCode)];
        for (int c = 0; c < kLowCode; ++c)
            f[size_t(c)] = float(lo * std::pow(double(c) / kLowCode, g));
        for (int c = kHighCode + 1; c < 256; ++c)
            f[size_t(c)] = float(hi * std::pow(double(c) / kHighCode, g));
    }
    ResponseFit out;
    out.response = CameraResponse::table(inverse);
    out.equivalentGamma = gammaSum / 3.0;

    // Agreement of the bracket with the fitted curve: per sampled pixel and channel, the spread
    // of ln(f(code) / t) over the images where the code is trusted.
    const cv::Size size = bracket.front().bgr8.size();
    const int step = std::max(1, int(std::sqrt(double(size.area()) / 4000.0)));
    double sq = 0;
    int n = 0;
    for (int y = step / 2; y < size.height; y += step)
        for (int x = step / 2; x < size.width; x += step)
            for (int ch = 0; ch < 3; ++ch) {
                std::vector<double> logE;
                for (const BracketImage& b : bracket) {
                    const int c = b.bgr8.at<cv::Vec3b>(y, x)[2 - ch];
                    if (c < kLowCode || c > kHighCode) continue;
                    logE.push_back(std::log(double(out.response.linear(ch, c))) -
                                   std::log(b.exposureSeconds));
                }
                if (logE.size() < 2) continue;
                double mean = 0;
                for (double v : logE) mean += v;
                mean /= double(logE.size());
                for (double v : logE) sq += (v - mean) * (v - mean);
                n += int(logE.size());
            }
    out.samplesUsed = n;
    out.logRadianceSpread = n > 0 ? std::sqrt(sq / n) : 0.0;
    return out;
}

}  // namespace mirage::calibration
