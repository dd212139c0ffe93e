#include <gtest/gtest.h>

#include <cmath>

#include <limits>

#include <fstream>

#include "core/Error.h"
#include "core/image/ImageIO.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

cv::Mat gradient() {
    cv::Mat m(16, 24, CV_32FC3);
    for (int y = 0; y < m.rows; ++y)
        for (int x = 0; x < m.cols; ++x)
            m.at<cv::Vec3f>(y, x) = {x / 23.0f * 4.0f, y / 15.0f, 0.25f};
    return m;
}

TEST(ImageIO, LinearFormatsRoundTripExactly) {
    auto dir = test::outputDir("imageio");
    cv::Mat img = gradient();  // values above 1 must survive the linear formats
    for (const char* ext : {".exr", ".pfm"}) {
        auto p = dir / (std::string("g") + ext);
        writeLinearRgb(p, img);
        cv::Mat back = readLinearRgb(p);
        ASSERT_EQ(back.type(), CV_32FC3) << ext;
        EXPECT_LT(cv::norm(back, img, cv::NORM_INF), 1e-6) << ext;
    }
}

TEST(ImageIO, PngIsSrgbEncodedAndClamped) {
    auto dir = test::outputDir("imageio_png");
    cv::Mat img = gradient();
    writeLinearRgb(dir / "g.png", img);
    cv::Mat back = readLinearRgb(dir / "g.png");
    cv::Mat clamped;
    cv::min(img, 1.0, clamped);
    // 8-bit sRGB quantisation: at most half an 8-bit step in encoded space.
    EXPECT_LT(cv::norm(back, clamped, cv::NORM_INF), 0.01);
    EXPECT_NEAR(linearToSrgb(srgbToLinear(0.5f)), 0.5f, 1e-6);
}

TEST(ImageIO, NanBecomesBlackInPng) {
    cv::Mat img(2, 2, CV_32FC3, cv::Scalar(std::nanf(""), 0.5f, 2.0f));
    cv::Mat bgr = linearRgbToSrgbBgr8(img);
    EXPECT_EQ(bgr.at<cv::Vec3b>(0, 0)[2], 0);    // R was NaN
    EXPECT_EQ(bgr.at<cv::Vec3b>(0, 0)[0], 255);  // B was 2.0, clamped
}

TEST(ImageIO, NonFiniteLinearPixelsAreRefusedNamingThePixel) {
    // A NaN in a static environment map spread through its integral into every lit pixel; now
    // the file is refused where it is read.
    const auto dir = test::outputDir("imageio_nan");
    for (const float bad : {std::nanf(""), std::numeric_limits<float>::infinity()}) {
        std::string pfm = "PF\n2 1\n-1.0\n";
        const float values[6] = {0.5f, 0.5f, 0.5f, 0.25f, bad, 0.25f};  // pixel (1, 0), G
        pfm.append(reinterpret_cast<const char*>(values), sizeof values);
        std::ofstream(dir / "env.pfm", std::ios::binary | std::ios::trunc) << pfm;
        try {
            readLinearRgb(dir / "env.pfm");
            ADD_FAILURE() << "a non-finite pixel was accepted";
        } catch (const FileError& e) {
            const std::string m = e.what();
            EXPECT_NE(m.find("env.pfm"), std::string::npos) << m;
            EXPECT_NE(m.find("pixel (1, 0) channel G"), std::string::npos) << m;
        }
    }
}

TEST(ImageIO, MissingAndUnknownFilesGiveFileErrors) {
    EXPECT_THROW(readLinearRgb("/nonexistent/x.exr"), FileError);
    auto dir = test::outputDir("imageio_bad");
    EXPECT_THROW(writeLinearRgb(dir / "x.bmpx", gradient()), FileError);
}

}  // namespace
}  // namespace mirage
