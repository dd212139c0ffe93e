// The camera response from an exposure bracket (calibration/ResponseFit.h): a bracket made with a
// known gamma curve is fitted back; a moving scene shows in the agreement figure; brackets that
// cannot give a response are refused with the reason.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include <opencv2/imgproc.hpp>

#include "calibration/ResponseFit.h"
#include "core/Error.h"

namespace mirage::calibration {
namespace {

// A still scene's radiance (R, G, B, relative) over three decades: a horizontal ramp in log
// space with a finer pattern on it, so every code appears at some exposure.
cv::Mat sceneRadiance(int w = 160, int h = 120) {
    cv::Mat r(h, w, CV_32FC3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double base = std::pow(10.0, -3.0 + 3.0 * x / (w - 1));
            const double pattern = 1.0 + 0.3 * std::sin(0.37 * y) * std::cos(0.21 * x);
            r.at<cv::Vec3f>(y, x) = {float(base * pattern * 0.8), float(base * pattern),
                                     float(base * pattern * 0.6)};
        }
    return r;
}

// The camera: radiance x time, gamma-encoded to 8 bits (with a little noise), BGR.
std::vector<BracketImage> bracketOf(const cv::Mat& radiance, double gamma, int shiftPerImage = 0,
                                    int images = 6) {
    std::mt19937 rng(3);
    std::normal_distribution<float> noise(0.0f, 0.4f);  // codes
    std::vector<BracketImage> out;
    double t = 1.0 / 8.0;
    for (int i = 0; i < images; ++i, t *= 2.0) {
        cv::Mat img(radiance.size(), CV_8UC3);
        for (int y = 0; y < radiance.rows; ++y)
            for (int x = 0; x < radiance.cols; ++x) {
                const cv::Vec3f e =
                    radiance.at<cv::Vec3f>(y, std::min(radiance.cols - 1, x + shiftPerImage * i));
                for (int k = 0; k < 3; ++k) {
                    const double v = std::clamp(e[k] * t, 0.0, 1.0);
                    const float code = float(255.0 * std::pow(v, 1.0 / gamma)) + noise(rng);
                    img.at<cv::Vec3b>(y, x)[2 - k] = cv::saturate_cast<uint8_t>(code);
                }
            }
        out.push_back({img, t, "image " + std::to_string(i)});
    }
    return out;
}

// Largest relative difference of two inverse responses over the trusted codes 16..239.
double worstRelativeError(const CameraResponse& a, const CameraResponse& b) {
    double worst = 0;
    for (int ch = 0; ch < 3; ++ch)
        for (int c = 16; c <= 239; ++c)
            worst = std::max(worst, std::abs(double(a.linear(ch, c)) / b.linear(ch, c) - 1.0));
    return worst;
}

TEST(ResponseFit, AGammaCameraIsFittedBack) {
    const CameraResponse truth = CameraResponse::gamma(2.4);
    const ResponseFit fit = fitCameraResponse(bracketOf(sceneRadiance(), 2.4));
    const double err = worstRelativeError(fit.response, truth);
    std::cout << "[ response ] gamma 2.4 bracket: equivalent gamma " << fit.equivalentGamma
              << ", worst relative error " << err << ", spread " << fit.logRadianceSpread
              << " over " << fit.samplesUsed << " samples\n";
    EXPECT_NEAR(fit.equivalentGamma, 2.4, 0.1);
    EXPECT_LT(err, 0.08);
    EXPECT_LT(fit.logRadianceSpread, 0.05);
    // The comparison can fail: the sRGB assumption is far from this camera.
    EXPECT_GT(worstRelativeError(CameraResponse::srgb(), truth), 0.3);
    // And another camera is told apart.
    const ResponseFit other = fitCameraResponse(bracketOf(sceneRadiance(), 1.8));
    EXPECT_NEAR(other.equivalentGamma, 1.8, 0.1);
    EXPECT_GT(worstRelativeError(other.response, truth), 0.3);
}

TEST(ResponseFit, AMovingSceneShowsInTheAgreement) {
    const ResponseFit still = fitCameraResponse(bracketOf(sceneRadiance(), 2.2));
    const ResponseFit moving = fitCameraResponse(bracketOf(sceneRadiance(), 2.2, 6));
    EXPECT_GT(moving.logRadianceSpread, 3.0 * still.logRadianceSpread)
        << still.logRadianceSpread << " vs " << moving.logRadianceSpread;
}

TEST(ResponseFit, BracketsThatCannotGiveAResponseAreRefused) {
    const cv::Mat radiance = sceneRadiance();
    auto expectRefused = [](const std::vector<BracketImage>& b, const std::string& why) {
        try {
            fitCameraResponse(b);
            ADD_FAILURE() << "accepted; expected: " << why;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
        }
    };
    expectRefused(bracketOf(radiance, 2.2, 0, 2), "at least 3");
    auto sameTimes = bracketOf(radiance, 2.2);
    for (auto& b : sameTimes) b.exposureSeconds = 0.01;
    expectRefused(sameTimes, "distinct exposure time");
    auto badTime = bracketOf(radiance, 2.2);
    badTime[2].exposureSeconds = NAN;
    expectRefused(badTime, "image 2: exposure time");
    auto sizes = bracketOf(radiance, 2.2);
    cv::resize(sizes[1].bgr8, sizes[1].bgr8, cv::Size(80, 60));
    expectRefused(sizes, "same size");
    // A flat grey card: a handful of codes, no curve.
    const cv::Mat flat(120, 160, CV_32FC3, cv::Scalar(0.05, 0.05, 0.05));
    expectRefused(bracketOf(flat, 2.2), "of the codes");
}

}  // namespace
}  // namespace mirage::calibration
