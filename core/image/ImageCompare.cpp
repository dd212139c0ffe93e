#include "core/image/ImageCompare.h"

#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "core/Error.h"

namespace mirage {

void checkComparable(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
    if (a.empty() || a.size() != b.size() || a.type() != b.type())
        throw Error("image comparison: the two images must be non-empty, of equal size and type");
    if (!mask.empty() && (mask.size() != a.size() || mask.type() != CV_8U))
        throw Error("image comparison: the mask must be CV_8U and of the images' size");
}

cv::Mat squaredErrorPerPixel(const cv::Mat& a, const cv::Mat& b, double peak) {
    checkComparable(a, b, {});
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

cv::Mat ssimMap(const cv::Mat& a, const cv::Mat& b, double peak) {
    checkComparable(a, b, {});
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

cv::Mat ssimPerPixel(const cv::Mat& a, const cv::Mat& b, double peak) {
    cv::Mat m = ssimMap(a, b, peak);
    m = m.reshape(1, int(m.total()));
    cv::Mat perPixel;
    cv::reduce(m, perPixel, 1, cv::REDUCE_AVG);
    return perPixel.reshape(1, a.rows);
}

double psnr(const cv::Mat& a, const cv::Mat& b, double peak, const cv::Mat& mask) {
    checkComparable(a, b, mask);
    const cv::Mat se = squaredErrorPerPixel(a, b, peak);
    const double pixels = mask.empty() ? double(a.total()) : double(cv::countNonZero(mask));
    if (pixels <= 0) return std::nan("");
    const double sum = mask.empty() ? cv::sum(se)[0] : cv::sum(se.clone().setTo(0, mask == 0))[0];
    const double mse = sum / (pixels * a.channels());  // in units of peak²
    if (mse <= 0) return std::numeric_limits<double>::infinity();
    return -10.0 * std::log10(mse);
}

double ssim(const cv::Mat& a, const cv::Mat& b, double peak, const cv::Mat& mask) {
    checkComparable(a, b, mask);
    const cv::Mat m = ssimPerPixel(a, b, peak);
    if (!mask.empty() && cv::countNonZero(mask) == 0) return std::nan("");
    return mask.empty() ? cv::mean(m)[0] : cv::mean(m, mask)[0];
}

}  // namespace mirage
