#include "render/evaluation/ImageComparison.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/Error.h"

namespace mirage::render {
namespace {

void checkPair(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
    if (a.empty() || a.size() != b.size() || a.type() != b.type())
        throw Error("image comparison: the two images must be non-empty, of equal size and type");
    if (!mask.empty() && (mask.size() != a.size() || mask.type() != CV_8U))
        throw Error("image comparison: the mask must be CV_8U and of the images' size");
}

// Per-pixel squared error summed over channels, in units of peak² (CV_64F, one channel).
cv::Mat squaredErrorMap(const cv::Mat& a, const cv::Mat& b, double peak) {
    cv::Mat fa, fb, d;
    a.convertTo(fa, CV_64F, 1.0 / peak);
    b.convertTo(fb, CV_64F, 1.0 / peak);
    d = fa - fb;
    d = d.mul(d);
    d = d.reshape(1, int(d.total()));
    cv::Mat perPixel;
    cv::reduce(d, perPixel, 1, cv::REDUCE_SUM);
    return perPixel.reshape(1, a.rows);
}

// Mean over channels of the SSIM map (CV_64F, one channel).
cv::Mat ssimPerPixel(const cv::Mat& a, const cv::Mat& b, double peak) {
    cv::Mat m = ssimMap(a, b, peak);
    m = m.reshape(1, int(m.total()));
    cv::Mat perPixel;
    cv::reduce(m, perPixel, 1, cv::REDUCE_AVG);
    return perPixel.reshape(1, a.rows);
}

}  // namespace

cv::Mat ssimMap(const cv::Mat& a, const cv::Mat& b, double peak) {
    checkPair(a, b, {});
    const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
    cv::Mat fa, fb;
    a.convertTo(fa, CV_64F, 1.0 / peak);
    b.convertTo(fb, CV_64F, 1.0 / peak);
    auto blur = [](const cv::Mat& m) {
        cv::Mat o;
        cv::GaussianBlur(m, o, cv::Size(11, 11), 1.5);
        return o;
    };
    const cv::Mat muA = blur(fa), muB = blur(fb);
    const cv::Mat muA2 = muA.mul(muA), muB2 = muB.mul(muB), muAB = muA.mul(muB);
    const cv::Mat sA = blur(fa.mul(fa)) - muA2, sB = blur(fb.mul(fb)) - muB2,
                  sAB = blur(fa.mul(fb)) - muAB;
    // Scalar::all: a bare double added to a multi-channel matrix would only reach channel 0.
    const cv::Scalar C1 = cv::Scalar::all(c1), C2 = cv::Scalar::all(c2);
    const cv::Mat num = (2 * muAB + C1).mul(2 * sAB + C2);
    const cv::Mat den = (muA2 + muB2 + C1).mul(sA + sB + C2);
    cv::Mat map;
    cv::divide(num, den, map);
    return map;
}

double psnr(const cv::Mat& a, const cv::Mat& b, double peak, const cv::Mat& mask) {
    ErrorAccumulator acc;
    acc.channels = a.channels();
    acc.add(a, b, peak, mask);
    return acc.psnrDb();
}

double ssim(const cv::Mat& a, const cv::Mat& b, double peak, const cv::Mat& mask) {
    checkPair(a, b, mask);
    const cv::Mat m = ssimPerPixel(a, b, peak);
    if (!mask.empty() && cv::countNonZero(mask) == 0) return std::nan("");
    return mask.empty() ? cv::mean(m)[0] : cv::mean(m, mask)[0];
}

void ErrorAccumulator::add(const cv::Mat& got, const cv::Mat& truth, double peak,
                           const cv::Mat& mask) {
    checkPair(got, truth, mask);
    channels = got.channels();
    const cv::Mat se = squaredErrorMap(got, truth, peak);
    const cv::Mat s = ssimPerPixel(got, truth, peak);
    if (mask.empty()) {
        squaredError += cv::sum(se)[0];
        ssimSum += cv::sum(s)[0];
        pixels += double(got.total());
    } else {
        const cv::Mat off = mask == 0;
        squaredError += cv::sum(se.clone().setTo(0, off))[0];
        ssimSum += cv::sum(s.clone().setTo(0, off))[0];
        pixels += cv::countNonZero(mask);
    }
}

double ErrorAccumulator::psnrDb() const {
    if (pixels <= 0) return std::nan("");
    const double mse = squaredError / (pixels * channels);
    if (mse <= 0) return std::numeric_limits<double>::infinity();
    return -10.0 * std::log10(mse);  // errors are in units of the peak: PSNR = 10 log10(1 / mse)
}

double ErrorAccumulator::meanSsim() const {
    return pixels > 0 ? ssimSum / pixels : std::nan("");
}

void CompositeErrorAccumulator::add(const cv::Mat& gotSrgb8, const cv::Mat& truthSrgb8,
                                    const cv::Mat& influence) {
    if (gotSrgb8.type() != CV_8UC3)
        throw Error("composite comparison: expects 8-bit BGR (sRGB) images");
    checkPair(gotSrgb8, truthSrgb8, influence);
    // The error maps once, summed over the frame and over the influenced pixels.
    const cv::Mat se = squaredErrorMap(gotSrgb8, truthSrgb8, 255.0);
    const cv::Mat s = ssimPerPixel(gotSrgb8, truthSrgb8, 255.0);
    frame.channels = influenced.channels = 3;
    frame.squaredError += cv::sum(se)[0];
    frame.ssimSum += cv::sum(s)[0];
    frame.pixels += double(gotSrgb8.total());
    const cv::Mat off = influence == 0;
    influenced.squaredError += cv::sum(se.clone().setTo(0, off))[0];
    influenced.ssimSum += cv::sum(s.clone().setTo(0, off))[0];
    influenced.pixels += cv::countNonZero(influence);
}

void CompositeErrorAccumulator::merge(const CompositeErrorAccumulator& other) {
    for (auto [mine, theirs] :
         {std::pair{&frame, &other.frame}, {&influenced, &other.influenced}}) {
        mine->squaredError += theirs->squaredError;
        mine->ssimSum += theirs->ssimSum;
        mine->pixels += theirs->pixels;
        mine->channels = theirs->channels;
    }
}

CompositeError CompositeErrorAccumulator::result() const {
    CompositeError e;
    e.psnrFrame = frame.psnrDb();
    e.ssimFrame = frame.meanSsim();
    e.psnrInfluenced = influenced.psnrDb();
    e.ssimInfluenced = influenced.meanSsim();
    e.influencedPixels = influenced.pixels;
    return e;
}

}  // namespace mirage::render
