// The flat-pattern renderer behind the synthetic views: its interpolated camera rays land where
// the exact camera model puts them (pinhole and fish-eye out to the image circle), sub-pixels mix
// in linear light, and a pattern edge lands where the camera model projects it.
#include <gtest/gtest.h>

#include <random>

#include "core/Error.h"
#include "core/camera/TexturedPlaneRenderer.h"
#include "core/image/ImageIO.h"
#include "tests/support/TestCameras.h"

namespace mirage {
namespace {

// Worst distance (pixels) between a pixel and the projection of the renderer's ray for it.
double worstRayErrorPx(const TexturedPlaneRenderer& r, int samples) {
    const auto& cam = r.camera();
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> ux(-0.5, cam.width - 0.5), uy(-0.5, cam.height - 0.5);
    double worst = 0;
    int valid = 0;
    for (int i = 0; i < samples; ++i) {
        const glm::dvec2 px{ux(rng), uy(rng)};
        const auto ray = r.rayAt(px);
        if (!ray) continue;
        const auto back = cam.project(*ray);
        if (!back) continue;
        ++valid;
        worst = std::max(worst, glm::length(*back - px));
    }
    EXPECT_GT(valid, samples / 2);
    return worst;
}

TEST(TexturedPlaneRenderer, InterpolatedRaysMatchTheCameraModel) {
    const TexturedPlaneRenderer pinhole(test::distortedWebcam640(), 3);
    EXPECT_LT(worstRayErrorPx(pinhole, 20000), 1e-3);
    // A 190-degree fish-eye whose image circle lies inside the image: rays up to 95 degrees.
    auto fish = test::fisheyeCamera(640, 480, 145, 145, 320, 240, {-0.03, 0.002, 0, 0});
    fish.maxFisheyeTheta = 95.0 * M_PI / 180.0;
    const TexturedPlaneRenderer fisheye(fish, 3);
    EXPECT_LT(worstRayErrorPx(fisheye, 20000), 2e-3);
}

// A pixel half covered by black ink (0) and half by white paper (255) shows the mean in linear
// light (sRGB 188), not the mean of the encoded values (128): how a sensor integrates light.
TEST(TexturedPlaneRenderer, AveragesInLinearLight) {
    const auto cam = test::pinholeCamera(64, 48, 100, 100, 31.5, 23.5);
    const TexturedPlaneRenderer r(cam, 4);
    // Left texel black, right texel white, 1 m x 1 m each, edge on the optical axis. At 10 m
    // the edge falls on x = 31.5, the border between pixels 31 and 32; shifted by half a pixel
    // (0.05 m) it splits pixel 32 in two.
    PlaneTexture tex;
    tex.image = (cv::Mat_<uint8_t>(1, 2) << 0, 255);
    tex.metresPerTexelX = tex.metresPerTexelY = 1.0;
    tex.filter = PlaneTexture::Filter::Nearest;
    tex.originMetres = {-1.0 + 0.05, -0.5};
    Pose T_camera_plane;
    T_camera_plane.translation = {0, 0, 10};
    PlaneShading shading;
    shading.background = 0;
    const cv::Mat img = r.render(tex, T_camera_plane, shading);
    const int half = int(std::lround(255.0f * linearToSrgb(0.5f)));
    EXPECT_NEAR(img.at<uint8_t>(24, 32), half, 3);
    EXPECT_EQ(img.at<uint8_t>(24, 30), 0);
    EXPECT_EQ(img.at<uint8_t>(24, 34), 255);
}

// A fish-eye view of a black/white edge: on each image row, the half-grey crossing lies where
// the camera model projects the edge line (within 0.05 px: the jittered sub-pixels estimate each
// pixel's coverage with a standard deviation of ~0.02 px at 8 x 8), far off-axis included.
TEST(TexturedPlaneRenderer, EdgeLandsWhereTheModelProjectsIt) {
    auto cam = test::fisheyeCamera(320, 240, 80, 80, 160, 120, {0.01, -0.004, 0, 0});
    const TexturedPlaneRenderer r(cam, 8);
    PlaneTexture tex;
    tex.image = (cv::Mat_<uint8_t>(1, 2) << 0, 255);
    tex.metresPerTexelX = tex.metresPerTexelY = 10.0;
    tex.filter = PlaneTexture::Filter::Nearest;
    tex.originMetres = {-10.0 + 0.3, -5.0};  // edge: the line x = 0.3 m in the plane z = 1 m
    Pose T_camera_plane;
    T_camera_plane.translation = {0, 0, 1};
    PlaneShading shading;
    shading.background = 0;
    const cv::Mat img = r.render(tex, T_camera_plane, shading);
    int rows = 0;
    for (int y = 40; y < 200; y += 10) {
        // The edge's column on this row from the pixels' black fractions in linear light: over
        // pixels x0..x1 straddling it, sum(1 - v) = e - (x0 - 0.5).
        int firstWhite = -1;
        for (int x = 0; x < img.cols && firstWhite < 0; ++x)
            if (img.at<uint8_t>(y, x) > 128) firstWhite = x;
        ASSERT_GT(firstWhite, 6) << "row " << y;
        const int x0 = firstWhite - 4, x1 = firstWhite + 4;
        double black = 0;
        for (int x = x0; x <= x1; ++x) black += 1.0 - srgbToLinear(img.at<uint8_t>(y, x) / 255.0f);
        const double crossing = x0 - 0.5 + black;
        // Where the camera model puts the edge on this row: bisection on the column for the ray
        // that meets the plane z = 1 m at x = 0.3 m.
        double lo = x0, hi = x1;
        for (int it = 0; it < 60; ++it) {
            const double mid = 0.5 * (lo + hi);
            const auto ray = cam.unproject({mid, double(y)});
            ASSERT_TRUE(ray && ray->z > 0);
            ((ray->x / ray->z) < 0.3 ? lo : hi) = mid;
        }
        EXPECT_NEAR(crossing, lo, 0.05) << "row " << y;
        ++rows;
    }
    EXPECT_GT(rows, 10);
}

TEST(TexturedPlaneRenderer, RefusesBadInput) {
    EXPECT_THROW(TexturedPlaneRenderer(CameraIntrinsics{}, 2), Error);
    const TexturedPlaneRenderer r(test::pinholeCamera(32, 24, 30, 30, 16, 12), 2);
    EXPECT_THROW(r.render(PlaneTexture{}, Pose{}), Error);
}

}  // namespace
}  // namespace mirage
