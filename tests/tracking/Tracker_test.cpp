#include <gtest/gtest.h>

#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "tests/tracking/SyntheticViews.h"
#include "tracking/Tracker.h"

namespace mirage::tracking {
namespace {

// A static camera whose frames differ only by sensor noise (sigma 3 levels): the filtered pose
// jitters less than the raw one, and a frame without tags resets the filter.
TEST(Tracker, StaticCameraJitterBeforeAndAfterFiltering) {
    const Board board = BoardLayout().makeBoard();
    const BoardRaster tex = renderBoard(board, 8000, false);
    const auto cam = testing::pinholeCamera();
    const Pose T = testing::lookAt({0.12, 0.42, 0.25}, {0, 0, 0});
    const cv::Mat clean = renderSyntheticBoardView(board, tex, cam, T);
    Tracker tracker(board, cam);
    cv::RNG rng(11);
    std::vector<glm::dvec3> rawT, filtT;
    std::vector<glm::dquat> rawR, filtR;
    for (int i = 0; i < 40; ++i) {
        cv::Mat noisy;
        cv::Mat noise(clean.size(), CV_16S);
        rng.fill(noise, cv::RNG::NORMAL, 0, 3);
        clean.convertTo(noisy, CV_16S);
        noisy += noise;
        noisy.convertTo(noisy, CV_8U);
        const TrackedFrame f = tracker.process(noisy, i / 30.0);
        ASSERT_EQ(f.estimate.state, TrackingState::Ok) << f.estimate.reason;
        if (i >= 10) {
            rawT.push_back(f.estimate.pose->translation);
            rawR.push_back(f.estimate.pose->rotation);
            filtT.push_back(f.filtered->translation);
            filtR.push_back(f.filtered->rotation);
        }
    }
    auto stdT = [](const std::vector<glm::dvec3>& v) {
        glm::dvec3 m(0.0);
        for (const auto& x : v) m += x / double(v.size());
        double s = 0;
        for (const auto& x : v) s += glm::dot(x - m, x - m);
        return std::sqrt(s / double(v.size()));
    };
    auto stdR = [](const std::vector<glm::dquat>& v) {
        double s = 0;
        for (const auto& q : v) {
            const double a = rotationAngleBetween(q, v.front());
            s += a * a;
        }
        return glm::degrees(std::sqrt(s / double(v.size())));
    };
    const double rt = stdT(rawT), ft = stdT(filtT), rr = stdR(rawR), fr = stdR(filtR);
    std::printf(
        "static jitter (30 frames): translation std raw %.4f mm, filtered %.4f mm; "
        "rotation spread raw %.5f deg, filtered %.5f deg\n",
        rt * 1e3, ft * 1e3, rr, fr);
    RecordProperty("jitter_translation_mm_raw", std::to_string(rt * 1e3));
    RecordProperty("jitter_translation_mm_filtered", std::to_string(ft * 1e3));
    // The predictive filter at rest (gain ~0.1): jitter down at least 3x.
    EXPECT_LT(ft, rt / 3);
    EXPECT_LT(fr, rr / 3);

    // A frame of noise: no_tags, the filter resets, the next ok frame is unfiltered.
    cv::Mat junk(clean.size(), CV_8U);
    rng.fill(junk, cv::RNG::UNIFORM, 0, 256);
    EXPECT_EQ(tracker.process(junk, 41 / 30.0).estimate.state, TrackingState::NoTags);
    const TrackedFrame after = tracker.process(clean, 42 / 30.0);
    ASSERT_EQ(after.estimate.state, TrackingState::Ok);
    EXPECT_NEAR(glm::length(after.filtered->translation - after.estimate.pose->translation), 0.0,
                1e-12);
}

TEST(Tracker, SharpnessSeparatesSharpAndBlurredImages) {
    const Board board = BoardLayout().makeBoard();
    const BoardRaster tex = renderBoard(board, 8000, false);
    const auto cam = testing::pinholeCamera();
    const cv::Mat img =
        renderSyntheticBoardView(board, tex, cam, testing::lookAt({0.0, 0.35, 0.2}, {0, 0, 0}));
    const double sharp = imageSharpness(img);
    cv::Mat blurred;
    cv::GaussianBlur(img, blurred, cv::Size(0, 0), 6.0);
    const double soft = imageSharpness(blurred);
    EXPECT_GT(sharp, 0.2);
    EXPECT_LT(soft, TrackerOptions().minSharpness);
    EXPECT_EQ(imageSharpness(cv::Mat(100, 100, CV_8U, cv::Scalar(128))), 0.0);
}

}  // namespace
}  // namespace mirage::tracking
