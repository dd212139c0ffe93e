#include "render/evaluation/ImageComparison.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/image/ImageIO.h"

namespace mirage::render {
void ErrorAccumulator::add(const cv::Mat& got, const cv::Mat& truth, double peak,
                           const cv::Mat& mask) {
    checkComparable(got, truth, mask);
    channels = got.channels();
    const cv::Mat se = squaredErrorPerPixel(got, truth, peak);
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

cv::Mat edgePixels(const cv::Mat& footageSrgb8, const cv::Mat& truthSrgb8, const cv::Mat& influence,
                   double threshold) {
    checkComparable(footageSrgb8, truthSrgb8, influence);
    cv::Mat change = srgbBgr8ToLinearRgb(truthSrgb8) - srgbBgr8ToLinearRgb(footageSrgb8);
    cv::Mat luma;  // linear RGB -> Rec. 709 luminance
    cv::transform(change, luma, cv::Matx13f(0.2126f, 0.7152f, 0.0722f));
    cv::Mat hi, lo;
    const cv::Mat k = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
    cv::dilate(luma, hi, k);
    cv::erode(luma, lo, k);
    cv::Mat edges = (hi - lo) > threshold;
    return edges & (influence > 0);
}

void CompositeErrorAccumulator::add(const cv::Mat& gotSrgb8, const cv::Mat& truthSrgb8,
                                    const cv::Mat& influence, const cv::Mat& edgeMask) {
    if (gotSrgb8.type() != CV_8UC3)
        throw Error("composite comparison: expects 8-bit BGR (sRGB) images");
    checkComparable(gotSrgb8, truthSrgb8, influence);
    // The error maps once, summed over the frame and over the influenced pixels.
    const cv::Mat se = squaredErrorPerPixel(gotSrgb8, truthSrgb8, 255.0);
    const cv::Mat s = ssimPerPixel(gotSrgb8, truthSrgb8, 255.0);
    frame.channels = influenced.channels = 3;
    frame.squaredError += cv::sum(se)[0];
    frame.ssimSum += cv::sum(s)[0];
    frame.pixels += double(gotSrgb8.total());
    const cv::Mat off = influence == 0;
    influenced.squaredError += cv::sum(se.clone().setTo(0, off))[0];
    influenced.ssimSum += cv::sum(s.clone().setTo(0, off))[0];
    influenced.pixels += cv::countNonZero(influence);
    edges.channels = 3;
    if (!edgeMask.empty()) {
        checkComparable(gotSrgb8, truthSrgb8, edgeMask);
        edges.squaredError += cv::sum(se.clone().setTo(0, edgeMask == 0))[0];
        edges.ssimSum += cv::sum(s.clone().setTo(0, edgeMask == 0))[0];
        edges.pixels += cv::countNonZero(edgeMask);
    }
}

void CompositeErrorAccumulator::merge(const CompositeErrorAccumulator& other) {
    for (auto [mine, theirs] : {std::pair{&frame, &other.frame},
                                {&influenced, &other.influenced},
                                {&edges, &other.edges}}) {
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
    e.psnrEdges = edges.psnrDb();
    e.edgePixels = edges.pixels;
    return e;
}

}  // namespace mirage::render
