// The image comparisons every image test relies on must be able to fail: a deliberately
// broken image scores below the floors the tests use.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "tests/support/TestSupport.h"

namespace mirage::test {
namespace {

cv::Mat pattern() {
    cv::Mat m(120, 160, CV_32FC3, cv::Scalar(0.2, 0.3, 0.4));
    cv::circle(m, {80, 60}, 30, cv::Scalar(0.9, 0.5, 0.1), -1, cv::LINE_AA);
    cv::rectangle(m, {10, 10}, {40, 100}, cv::Scalar(0.05, 0.6, 0.05), -1);
    return m;
}

TEST(ImageCompare, IdenticalImagesScorePerfect) {
    cv::Mat a = pattern();
    EXPECT_TRUE(std::isinf(psnr(a, a, 1.0)));
    EXPECT_NEAR(ssim(a, a, 1.0), 1.0, 1e-9);
    EXPECT_EQ(percentileAbsDiff(a, a, 0.99), 0.0);
}

TEST(ImageCompare, SmallNoisePassesTypicalFloors) {
    cv::Mat a = pattern(), noise(a.size(), a.type()), b;
    cv::randn(noise, 0, 0.005);
    b = a + noise;
    EXPECT_GT(psnr(a, b, 1.0), 40.0);
    EXPECT_GT(ssim(a, b, 1.0), 0.95);
}

TEST(ImageCompare, BrokenImageFailsTypicalFloors) {
    cv::Mat a = pattern(), b = pattern();
    cv::circle(b, {80, 60}, 30, cv::Scalar(0.2, 0.3, 0.4), -1);  // the object is missing
    EXPECT_LT(psnr(a, b, 1.0), 30.0);
    EXPECT_LT(ssim(a, b, 1.0), 0.95);
    EXPECT_GT(percentileAbsDiff(a, b, 0.99), 0.3);
}

// SSIM's stabilising constants reach every channel: two identical flat black colour images are a
// perfect match (with the constants on channel 0 only, green and blue would score 0/0 -> 0).
TEST(ImageCompare, FlatColourImagesScorePerfectInEveryChannel) {
    const cv::Mat black(40, 40, CV_8UC3, cv::Scalar::all(0));
    EXPECT_NEAR(ssim(black, black, 255.0), 1.0, 1e-9);
    const cv::Mat teal(40, 40, CV_8UC3, cv::Scalar(90, 120, 0));
    EXPECT_NEAR(ssim(teal, teal, 255.0), 1.0, 1e-9);
}

}  // namespace
}  // namespace mirage::test
